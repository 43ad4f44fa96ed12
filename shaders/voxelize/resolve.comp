#version 450 core
// Voxelization, stage 4: mean radiance = fixed-point sum / count; occupancy in alpha.
// Colour premultiplied by occupancy (empty voxels are all zero).
layout(local_size_x = 4, local_size_y = 4, local_size_z = 4) in;

layout(r32ui, binding = 0) uniform readonly uimage3D u_sumR;
layout(r32ui, binding = 1) uniform readonly uimage3D u_sumG;
layout(r32ui, binding = 2) uniform readonly uimage3D u_sumB;
layout(r32ui, binding = 3) uniform readonly uimage3D u_count;
layout(rgba16f, binding = 4) uniform writeonly image3D u_radiance;

const float kFixedScale = 512.0;  // keep in sync with sums.glsl

void main() {
    ivec3 v = ivec3(gl_GlobalInvocationID);
    if (any(greaterThanEqual(v, imageSize(u_radiance)))) return;
    uint n = imageLoad(u_count, v).r;
    vec4 value = vec4(0.0);
    if (n > 0u) {
        vec3 sum = vec3(imageLoad(u_sumR, v).r, imageLoad(u_sumG, v).r, imageLoad(u_sumB, v).r);
        value = vec4(sum / (kFixedScale * float(n)), 1.0);
    }
    imageStore(u_radiance, v, value);
}
