#version 450 core
#include "../../outside.glsl"
void main() {}
