#version 450 core
// Per-pixel diffuse cone tracing: every pixel (stride 1), or one pixel per stride×stride
// block: then pixel ij traces the G-buffer texel stride·ij + stride/2 (traceTexel in
// upsample.glsl) and also writes that surface's plane for upsample.frag. Alpha: the
// cone-traced ambient visibility, or (cone_trace.lamp) the lamp's projected solid angle.
#include "common/frame.glsl"
#include "trace.glsl"
#if KILN_LAMP_IN_ALPHA
#include "common/light.glsl"
#endif
#include "upsample.glsl"

layout(binding = 0) uniform sampler2D u_normal;
layout(binding = 1) uniform sampler2D u_depth;
uniform int u_stride;

layout(location = 0) out vec4 o_indirect;
layout(location = 1) out vec4 o_plane;  // xyz = unit normal, w = n·p; 0 off geometry

void main() {
    ivec2 src = traceTexel(ivec2(gl_FragCoord.xy), u_stride);
    vec4 n4 = texelFetch(u_normal, src, 0);
    if (n4.w < 0.5) {
        o_indirect = vec4(0.0, 0.0, 0.0, 1.0);
        o_plane = vec4(0.0);
        return;
    }
    vec3 p = worldAtTexel(u_depth, src);
    vec3 n = normalize(n4.xyz);
    o_indirect = traceDiffuse(p, n);
#if KILN_LAMP_IN_ALPHA
    // The lamp's unshadowed irradiance ÷ its radiance (smooth on a surface, like the
    // indirect light): traced here at one pixel in stride², upsampled with it.
    o_indirect.a = lampProjectedSolidAngle(p, n);
#endif
    o_plane = vec4(n, dot(n, p));
}
