#version 450 core
// Bright pass: what exceeds the threshold of the emitted radiance (the lamp, the
// fireballs, burning marbles and particles), at half resolution.
in vec2 v_uv;
layout(location = 0) out vec4 o_color;
layout(binding = 0) uniform sampler2D u_source;
uniform float u_threshold;
void main() {
    vec3 c = texture(u_source, v_uv).rgb;
    float peak = max(c.r, max(c.g, c.b));
    o_color = vec4(c * (max(peak - u_threshold, 0.0) / max(peak, 1e-6)), 1.0);
}
