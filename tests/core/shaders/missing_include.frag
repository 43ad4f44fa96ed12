#version 450 core
#include "inc/missing.glsl"
void main() {}
