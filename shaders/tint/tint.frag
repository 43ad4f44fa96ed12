#version 450 core
layout(binding = 0) uniform sampler2D u_color;
uniform vec3 u_tint;
in vec2 v_uv;                                         // from common/fullscreen.vert
layout(location = 0) out vec4 o_color;
void main() { o_color = vec4(texture(u_color, v_uv).rgb * u_tint, 1.0); }
