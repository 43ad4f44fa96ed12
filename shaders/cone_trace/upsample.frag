#version 450 core
// Depth- and normal-aware upsample of a strided trace, to full or half resolution
// (u_outputStep; half: each output pixel stands for one G-buffer texel of its 2×2
// block and composite's bilinear lookup does the rest). Each output pixel blends the
// 2×2 nearest samples with bilinear weights × how well each sample's surface matches
// its own: normal agreement (cos⁸) and the pixel's distance from the sample's tangent
// plane (the plane comes with the sample, so a tap is two fetches and no matrix).
// None of the four matches (thin parts, a marble far off): the nearest sample, one of
// the four.
// No wider search for those few pixels: llvmpipe runs both sides of a divergent
// branch under lane masks, so a fallback that almost never runs still costs every
// pixel its taps (a 3×3 search cost far more than the handful of pixels it served).
#include "common/frame.glsl"
#include "upsample.glsl"

layout(binding = 0) uniform sampler2D u_normal;
layout(binding = 1) uniform sampler2D u_depth;
layout(binding = 4) uniform sampler2D u_samples;
layout(binding = 5) uniform sampler2D u_planes;
uniform int u_stride;      // G-buffer texels per sample (per side)
uniform int u_outputStep;  // G-buffer texels per output pixel: 1, or 2 for a half-size output
uniform float u_planeTolerance;  // world units

layout(location = 0) out vec4 o_indirect;

float surfaceMatch(vec3 n, vec3 p, ivec2 h) {
    vec4 plane = texelFetch(u_planes, h, 0);
    float c = max(dot(n, plane.xyz), 0.0);  // 0 where the sample saw no geometry
    c *= c;
    c *= c;
    return c * c * exp(-abs(dot(plane.xyz, p - u_voxelVolume.xyz) - plane.w) / u_planeTolerance);
}

void main() {
    // The G-buffer texel this output pixel stands for (its own one, or one of its 2×2).
    ivec2 px = traceTexel(ivec2(gl_FragCoord.xy), u_outputStep);
    vec4 n4 = texelFetch(u_normal, px, 0);
    if (n4.w < 0.5) {
        o_indirect = vec4(0.0, 0.0, 0.0, 1.0);
        return;
    }
    vec3 n = normalize(n4.xyz);
    vec3 p = worldAtTexel(u_depth, px);
    ivec2 last = textureSize(u_samples, 0) - 1;
    // Sample h sits at pixel stride·h + stride/2: px in sample units.
    vec2 u = (vec2(px) - float(u_stride / 2)) / float(u_stride);
    ivec2 h0 = ivec2(floor(u));
    vec2 f = u - vec2(h0);
    // The nearest sample, round(u), is tap h0 + (round(u) − h0), an offset of 0 or 1: no
    // fetch of its own.
    ivec2 nearestOffset = ivec2(round(u)) - h0;
    int nearestTap = nearestOffset.x + 2 * nearestOffset.y;
    vec4 sum = vec4(0.0), nearest = vec4(0.0);
    float wsum = 0.0;
    for (int k = 0; k < 4; ++k) {
        ivec2 o = ivec2(k & 1, k >> 1);
        ivec2 h = clamp(h0 + o, ivec2(0), last);
        float bil = (o.x == 1 ? f.x : 1.0 - f.x) * (o.y == 1 ? f.y : 1.0 - f.y);
        float w = (bil + 1e-3) * surfaceMatch(n, p, h);
        vec4 sampled = texelFetch(u_samples, h, 0);
        sum += w * sampled;
        wsum += w;
        if (k == nearestTap) nearest = sampled;
    }
    o_indirect = wsum > 1e-5 ? sum / wsum : nearest;
}
