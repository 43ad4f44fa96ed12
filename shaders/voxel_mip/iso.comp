#version 450 core
// Isotropic mip level: each parent = the mean of its 2×2×2 children (premultiplied
// colour and opacity). Along an axis the grid is one voxel across already (a flat
// scene's), the one child counts twice.
layout(local_size_x = 4, local_size_y = 4, local_size_z = 4) in;
layout(rgba16f, binding = 0) uniform readonly image3D u_src;
layout(rgba16f, binding = 1) uniform writeonly image3D u_dst;

void main() {
    ivec3 v = ivec3(gl_GlobalInvocationID);
    if (any(greaterThanEqual(v, imageSize(u_dst)))) return;
    vec4 sum = vec4(0.0);
    ivec3 last = imageSize(u_src) - 1;
    for (int i = 0; i < 8; ++i) sum += imageLoad(u_src, min(2 * v + ivec3(i & 1, (i >> 1) & 1, i >> 2), last));
    imageStore(u_dst, v, sum * 0.125);
}
