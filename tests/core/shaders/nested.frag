#version 450 core
#include "inc/a.glsl"
out vec4 o_color;
void main() { o_color = vec4(a(), 1.0); }
