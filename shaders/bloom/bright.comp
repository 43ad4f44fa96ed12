#version 450 core
// Bright-pass and 2× downsample in one: each invocation takes the mean of one 2×2 block
// of the full-resolution input (one bilinear lookup at its centre), keeps its part above
// the threshold (colour scaled by (lum − threshold) / lum) and stores the
// half-resolution texel — the threshold after the mean, as engines' prefilters do: four
// texel fetches, each thresholded, cost llvmpipe 0.5 ms more at 720² (the blur hides
// the difference). An invocation whose block passes also raises a flag, which the blur
// reads to write black without a tap when nothing passes. No reduction in shared
// memory: on llvmpipe every barrier() suspends and resumes each invocation, and the
// seven of a 64-wide tree cost more than the whole bright-pass (measured); an atomicOr
// from the few bright blocks costs nothing (a loop that skips them where no lane
// passes saved nothing either). Drawn as a fragment shader instead, the pass cost more.
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
    vec3 c = textureLod(u_color, vec2(2 * q + 1) / vec2(size), 0.0).rgb;
    float l = dot(c, vec3(0.2126, 0.7152, 0.0722));
    bool bright = l > u_threshold;  // NaN is not bright
    vec3 part = bright ? c * ((l - u_threshold) / l) : vec3(0.0);
    if (all(lessThan(q, imageSize(u_bright)))) imageStore(u_bright, q, vec4(part, 1.0));
    if (bright) {
        atomicOr(u_anyBright, 1u);
        atomicMin(u_minX, uint(q.x)), atomicMin(u_minY, uint(q.y));
        atomicMax(u_maxX, uint(q.x)), atomicMax(u_maxY, uint(q.y));
    }
}
