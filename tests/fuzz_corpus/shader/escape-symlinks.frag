#version 450
#include "escape.glsl"
#include "escape_dir/inc.glsl"
#include "../outside.glsl"
#include "loop_a.glsl"
void main() {}
