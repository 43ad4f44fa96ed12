#version 450 core
// Eight images in units 0-7 and a storage block at binding 7: exactly what OpenGL 4.5
// guarantees, so nothing to report.
layout(local_size_x = 1) in;
layout(r32ui, binding = 0) uniform uimage2D u_images[8];
layout(std430, binding = 7) buffer Counts { uint counts[]; };
void main() {
    uint sum = 0u;
    for (int i = 0; i < 8; ++i) sum += imageLoad(u_images[i], ivec2(0)).r;
    atomicAdd(counts[0], sum);
}
