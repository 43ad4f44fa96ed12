#version 450 core
// Bright-pass and 2× downsample in one: each invocation averages one 2×2 block of the
// full-resolution input, each texel first reduced to its part above the threshold
// (colour scaled by (lum − threshold) / lum), and stores the half-resolution texel.
// An invocation whose block has a texel above the threshold also raises a flag, which
// the blur reads to write black without a tap when nothing passes. No reduction in
// shared memory: on llvmpipe every barrier() suspends and resumes each invocation, and
// the seven of a 64-wide tree cost more than the whole bright-pass (measured); an
// atomicOr from the few bright blocks costs nothing.
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
    vec3 sum = vec3(0.0);
    float m = 0.0;
    for (int k = 0; k < 4; ++k) {
        vec3 c = texelFetch(u_color, min(2 * q + ivec2(k & 1, k >> 1), size - 1), 0).rgb;
        float l = dot(c, vec3(0.2126, 0.7152, 0.0722));
        if (l > m) m = l;  // NaN never wins (GLSL's max() leaves NaN undefined)
        sum += l > u_threshold ? c * ((l - u_threshold) / l) : vec3(0.0);
    }
    if (all(lessThan(q, imageSize(u_bright)))) imageStore(u_bright, q, vec4(0.25 * sum, 1.0));
    if (m > u_threshold) {
        atomicOr(u_anyBright, 1u);
        atomicMin(u_minX, uint(q.x)), atomicMin(u_minY, uint(q.y));
        atomicMax(u_maxX, uint(q.x)), atomicMax(u_maxY, uint(q.y));
    }
}
