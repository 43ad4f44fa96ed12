#version 450 core
// One axis of the separable Gaussian (σ = u_sigma, 2·radius+1 taps, weights
// normalised) over the half-resolution bright pass (bloom/bright.comp). Drawn only
// when something passed the threshold (bloom/blur.vert).
layout(binding = 0) uniform sampler2D u_src;
uniform vec2 u_direction;
uniform int u_radius;
uniform float u_sigma;
uniform float u_gain;

layout(location = 0) out vec4 o_color;

void main() {
    ivec2 p = ivec2(gl_FragCoord.xy);
    ivec2 last = textureSize(u_src, 0) - 1;
    vec3 sum = vec3(0.0);
    float wsum = 0.0;
    for (int i = -u_radius; i <= u_radius; ++i) {
        float w = exp(-float(i * i) / (2.0 * u_sigma * u_sigma));
        sum += w * texelFetch(u_src, clamp(p + ivec2(u_direction) * i, ivec2(0), last), 0).rgb;
        wsum += w;
    }
    o_color = vec4(u_gain * sum / wsum, 1.0);
}
