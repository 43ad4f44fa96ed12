#version 450 core
#include "inc/cycle_1.glsl"
void main() {}
