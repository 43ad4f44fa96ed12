#version 450 core
// Per-pixel diffuse cone tracing (full resolution, or every second pixel in x and y
// when half_res: then pixel ij traces the G-buffer texel 2·ij and upsample.frag fills
// the full-resolution output).
#include "common/frame.glsl"
#include "trace.glsl"

layout(binding = 0) uniform sampler2D u_normal;
layout(binding = 1) uniform sampler2D u_depth;
uniform int u_stride;  // 1 full resolution, 2 half

layout(location = 0) out vec4 o_indirect;

void main() {
    ivec2 src = ivec2(gl_FragCoord.xy) * u_stride;
    vec4 n4 = texelFetch(u_normal, src, 0);
    if (n4.w < 0.5) {
        o_indirect = vec4(0.0, 0.0, 0.0, 1.0);
        return;
    }
    float depth = texelFetch(u_depth, src, 0).r;
    vec2 ndc = (vec2(src) + 0.5) * u_outputSize.zw * 2.0 - 1.0;
    vec4 w = u_invViewProj * vec4(ndc, depth * 2.0 - 1.0, 1.0);
    vec3 p = w.xyz / w.w;
    o_indirect = traceDiffuse(p, normalize(n4.xyz));
}
