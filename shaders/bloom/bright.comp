#version 450 core
// Bright-pass and 2× downsample in one: each invocation takes the mean of one 2×2 block
// of the full-resolution input (one bilinear lookup at its centre), keeps its part above
// the threshold (colour scaled by (lum − threshold) / lum) and stores the
// half-resolution texel — the threshold after the mean, as engines' prefilters do: four
// texel fetches, each thresholded, cost llvmpipe more (the blur hides the difference).
// An invocation whose block passes also raises a flag, which the blur
// reads to write black without a tap when nothing passes. No reduction in shared
// memory: on llvmpipe every barrier() suspends and resumes each invocation, and the
// seven of a 64-wide tree cost more than the whole bright-pass. Five atomics from every
// bright texel are dear with many fireballs' sparks on screen (threads contending for
// one cache line): each is taken only where it would change the value, which after the
// first few texels is almost never.
// KILN_BRIGHT_SPARSE 1: only the bright texels are stored, over the rectangle bloom.cpp
// cleared (llvmpipe skips a masked lane's store, so the bright-pass is cheaper on a CPU
// rasterizer). 0: every texel is stored, dark ones black, and nothing is
// cleared (on a GPU the cleared texture cost more than the stores: bloom.cpp's
// bright_stores). Drawn as a fragment shader instead, the pass cost more.
#ifndef KILN_BRIGHT_SPARSE
#define KILN_BRIGHT_SPARSE 1
#endif
#include "common/luminance.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0) uniform sampler2D u_color;
layout(binding = 0, rgba16f) uniform writeonly image2D u_bright;
// The flag, and the rectangle of the texels above the threshold (bloom/blur.vert draws
// only round it).
layout(std430, binding = 1) buffer AnyBright { uint u_anyBright, u_minX, u_minY, u_maxX, u_maxY; };
uniform float u_threshold;
uniform ivec2 u_origin;  // the rectangle dispatched: all of it, or a part to redraw

void main() {
    ivec2 size = textureSize(u_color, 0);
    ivec2 q = u_origin + ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(q, imageSize(u_bright)))) return;
    vec3 c = textureLod(u_color, vec2(2 * q + 1) / vec2(size), 0.0).rgb;
    float l = kilnLuminance(c);
    if (!(l > u_threshold)) {  // NaN is not bright either
#if !KILN_BRIGHT_SPARSE
        imageStore(u_bright, q, vec4(0.0, 0.0, 0.0, 1.0));
#endif
        return;  // sparse: bloom.cpp cleared the texel
    }
    imageStore(u_bright, q, vec4(c * ((l - u_threshold) / l), 1.0));
    // Each atomic only where it would change the value: they only ever grow the
    // rectangle, so a stale read errs towards taking one, never past it.
    if (u_anyBright == 0u) atomicOr(u_anyBright, 1u);
    if (uint(q.x) < u_minX) atomicMin(u_minX, uint(q.x));
    if (uint(q.y) < u_minY) atomicMin(u_minY, uint(q.y));
    if (uint(q.x) > u_maxX) atomicMax(u_maxX, uint(q.x));
    if (uint(q.y) > u_maxY) atomicMax(u_maxY, uint(q.y));
}
