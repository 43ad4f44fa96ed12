#version 450 core
#include "inc/b.glsl"
#include "inc/broken.glsl"
out vec4 o_color;
void main() { o_color = vec4(broken(), 1.0); }
