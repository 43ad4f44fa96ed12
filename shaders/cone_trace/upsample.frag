#version 450 core
// Depth- and normal-aware upsample of the half-resolution trace: each output pixel
// blends the 2×2 nearest half-resolution samples with bilinear weights × how well each
// sample's surface matches its own (normal agreement, distance from its tangent
// plane). Half pixel ij traced the G-buffer texel 2·ij (cone_trace.frag), so the
// comparison uses the G-buffer at exactly those texels. No sample matches: the
// nearest one.
#include "common/frame.glsl"

layout(binding = 0) uniform sampler2D u_normal;
layout(binding = 1) uniform sampler2D u_depth;
layout(binding = 4) uniform sampler2D u_half;
uniform float u_planeTolerance;  // world units

layout(location = 0) out vec4 o_indirect;

vec3 worldAt(ivec2 px) {
    float depth = texelFetch(u_depth, px, 0).r;
    vec2 ndc = (vec2(px) + 0.5) * u_outputSize.zw * 2.0 - 1.0;
    vec4 w = u_invViewProj * vec4(ndc, depth * 2.0 - 1.0, 1.0);
    return w.xyz / w.w;
}

void main() {
    ivec2 px = ivec2(gl_FragCoord.xy);
    vec4 n4 = texelFetch(u_normal, px, 0);
    if (n4.w < 0.5) {
        o_indirect = vec4(0.0, 0.0, 0.0, 1.0);
        return;
    }
    vec3 n = normalize(n4.xyz);
    vec3 p = worldAt(px);
    ivec2 halfSize = textureSize(u_half, 0);
    ivec2 h0 = px >> 1;
    vec2 f = vec2(px & 1) * 0.5;
    vec4 sum = vec4(0.0);
    float wsum = 0.0;
    for (int k = 0; k < 4; ++k) {
        ivec2 o = ivec2(k & 1, k >> 1);
        ivec2 h = min(h0 + o, halfSize - 1);
        ivec2 src = min(h * 2, ivec2(u_outputSize.xy) - 1);
        vec4 sn = texelFetch(u_normal, src, 0);
        float bil = (o.x == 1 ? f.x : 1.0 - f.x) * (o.y == 1 ? f.y : 1.0 - f.y);
        float wn = sn.w > 0.5 ? pow(max(dot(n, normalize(sn.xyz)), 0.0), 8.0) : 0.0;
        float plane = abs(dot(n, worldAt(src) - p));
        float wp = exp(-plane / u_planeTolerance);
        float weight = bil * wn * wp;
        sum += weight * texelFetch(u_half, h, 0);
        wsum += weight;
    }
    o_indirect = wsum > 1e-4 ? sum / wsum : texelFetch(u_half, min(h0, halfSize - 1), 0);
}
