#version 450 core
// One level of voxelize.fire's mips: each texel the mean of the 2×2×2 below it (the
// particles' optical depth across a level-0 voxel, averaged: what a cone as wide as the
// texel sees). A compute pass, not glGenerateTextureMipmap: NVIDIA's driver spent GPU
// time and far more CPU time on it for this 32³ R16F volume.
layout(local_size_x = 4, local_size_y = 4, local_size_z = 4) in;

layout(r16f, binding = 0) uniform readonly image3D u_finer;
layout(r16f, binding = 1) uniform writeonly image3D u_coarser;

void main() {
    ivec3 v = ivec3(gl_GlobalInvocationID);
    if (any(greaterThanEqual(v, imageSize(u_coarser)))) return;
    float sum = 0.0;
    for (int k = 0; k < 8; ++k) sum += imageLoad(u_finer, 2 * v + ivec3(k & 1, (k >> 1) & 1, k >> 2)).r;
    imageStore(u_coarser, v, vec4(sum * 0.125));
}
