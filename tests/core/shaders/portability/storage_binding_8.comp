#version 450 core
// A storage block at binding 8: one past OpenGL 4.5's guaranteed 0-7.
layout(local_size_x = 1) in;
layout(std430, binding = 8) buffer Counts { uint counts[]; };
void main() { atomicAdd(counts[0], 1u); }
