#version 450 core
// One axis of the separable Gaussian (2·KILN_BLUR_RADIUS+1 taps, weights normalised) over the half-resolution bright pass (bloom/bright.comp). Drawn only
// when something passed the threshold (bloom/blur.vert).
layout(binding = 0) uniform sampler2D u_src;
uniform vec2 u_direction;
// The taps' weights, normalised (bloom.cpp): w[|i|] for tap i. KILN_BLUR_RADIUS is a
// define, so the loop unrolls and no exp() runs per fragment (the loop over a uniform
// radius with an exp() a tap was far dearer on llvmpipe).
uniform float u_weights[KILN_BLUR_RADIUS + 1];
uniform float u_gain;

layout(location = 0) out vec4 o_color;

void main() {
    ivec2 p = ivec2(gl_FragCoord.xy);
    ivec2 last = textureSize(u_src, 0) - 1;
    ivec2 step = ivec2(u_direction);
    vec3 sum = u_weights[0] * texelFetch(u_src, p, 0).rgb;
    for (int i = 1; i <= KILN_BLUR_RADIUS; ++i)
        sum += u_weights[i] * (texelFetch(u_src, clamp(p + step * i, ivec2(0), last), 0).rgb +
                               texelFetch(u_src, clamp(p - step * i, ivec2(0), last), 0).rgb);
    o_color = vec4(u_gain * sum, 1.0);
}
