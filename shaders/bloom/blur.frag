#version 450 core
// One axis of the separable Gaussian (σ = u_sigma, 2·radius+1 taps, weights
// normalised), at half resolution. With u_brightPass the source is the full-resolution
// input: each tap is the mean of its 2×2 block, each texel first reduced to its part
// above the threshold (colour scaled by (lum − threshold) / lum), so downsample +
// bright-pass + horizontal blur are one pass.
layout(binding = 0) uniform sampler2D u_src;
uniform vec2 u_direction;
uniform int u_radius;
uniform float u_threshold;
uniform float u_sigma;
uniform float u_gain;
uniform int u_brightPass;
// The input's brightest luminance (bloom/max.comp): nothing above the threshold ⇒ black.
layout(std430, binding = 1) readonly buffer MaxLum { uint u_maxBits; };

layout(location = 0) out vec4 o_color;

vec3 bright(vec3 c) {
    float l = dot(c, vec3(0.2126, 0.7152, 0.0722));
    return l > u_threshold ? c * ((l - u_threshold) / l) : vec3(0.0);
}

vec3 tap(ivec2 q) {
    if (u_brightPass == 0) return texelFetch(u_src, q, 0).rgb;
    ivec2 size = textureSize(u_src, 0) - 1;
    ivec2 b = 2 * q;
    return 0.25 * (bright(texelFetch(u_src, min(b, size), 0).rgb) + bright(texelFetch(u_src, min(b + ivec2(1, 0), size), 0).rgb)
                 + bright(texelFetch(u_src, min(b + ivec2(0, 1), size), 0).rgb) + bright(texelFetch(u_src, min(b + 1, size), 0).rgb));
}

void main() {
    if (!(uintBitsToFloat(u_maxBits) > u_threshold)) {
        o_color = vec4(0.0, 0.0, 0.0, 1.0);
        return;
    }
    ivec2 p = ivec2(gl_FragCoord.xy);
    ivec2 size = u_brightPass == 1 ? (textureSize(u_src, 0) + 1) / 2 : textureSize(u_src, 0);
    vec3 sum = vec3(0.0);
    float wsum = 0.0;
    for (int i = -u_radius; i <= u_radius; ++i) {
        ivec2 q = clamp(p + ivec2(u_direction) * i, ivec2(0), size - 1);
        float w = exp(-float(i * i) / (2.0 * u_sigma * u_sigma));
        sum += w * tap(q);
        wsum += w;
    }
    o_color = vec4(u_gain * sum / wsum, 1.0);
}
