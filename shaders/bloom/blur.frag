#version 450 core
// One direction of a separable Gaussian, (2·radius + 1) taps, σ = radius / 2.
in vec2 v_uv;
layout(location = 0) out vec4 o_color;
layout(binding = 0) uniform sampler2D u_source;
uniform vec2 u_direction;   // one texel along x or y
uniform int u_radius;
uniform float u_gain;
void main() {
    float sigma = max(float(u_radius) * 0.5, 0.5);
    vec3 sum = vec3(0.0);
    float total = 0.0;
    for (int i = -u_radius; i <= u_radius; ++i) {
        float w = exp(-0.5 * float(i * i) / (sigma * sigma));
        sum += w * texture(u_source, v_uv + float(i) * u_direction).rgb;
        total += w;
    }
    o_color = vec4(sum / total * u_gain, 1.0);
}
