#version 450 core
// Image unit 9: links under llvmpipe (32 units), not on a driver with OpenGL 4.5's 8.
layout(local_size_x = 1) in;
layout(r32ui, binding = 0) uniform uimage2D u_first;
layout(r32ui, binding = 9) uniform uimage2D u_tenth;
void main() { imageAtomicAdd(u_tenth, ivec2(0), imageLoad(u_first, ivec2(0)).r); }
