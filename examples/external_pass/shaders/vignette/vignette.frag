#version 450 core
#include "common/frame.glsl"                          // Kiln's shipped shaders: u_outputSize
layout(binding = 0) uniform sampler2D u_color;
uniform float u_strength;
in vec2 v_uv;                                         // from common/fullscreen.vert (shipped)
layout(location = 0) out vec4 o_color;
void main() {
    // Round on any aspect: measured in units of the longer side.
    vec2 fromCentre = (v_uv - 0.5) * u_outputSize.xy / max(u_outputSize.x, u_outputSize.y);
    o_color = vec4(texture(u_color, v_uv).rgb * (1.0 - u_strength * 2.0 * dot(fromCentre, fromCentre)), 1.0);
}
