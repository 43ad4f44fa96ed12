#version 450 core
// Voxelization, stage 4: mean radiance = fixed-point sum / count; occupancy in alpha.
// Colour premultiplied by occupancy (empty voxels are all zero). The surfaces' mean
// albedo and mean normal over the same count: a voxel that also holds particles (which
// reflect nothing) reflects that much less, as its mean radiance is that much more
// emission.
layout(local_size_x = 4, local_size_y = 4, local_size_z = 4) in;

#include "sums.glsl"  // the accumulators (image units 0–9) and their fixed-point scales
layout(rgba16f, binding = 10) uniform writeonly image3D u_radiance;
layout(rgba8, binding = 11) uniform writeonly image3D u_albedo;
layout(rgba16f, binding = 12) uniform writeonly image3D u_normal;

void main() {
    ivec3 v = ivec3(gl_GlobalInvocationID);
    if (any(greaterThanEqual(v, imageSize(u_radiance)))) return;
    uint n = imageLoad(u_count, v).r;
    vec4 value = vec4(0.0), albedo = vec4(0.0), normal = vec4(0.0);
    if (n > 0u) {
        vec3 sum = vec3(imageLoad(u_sumR, v).r, imageLoad(u_sumG, v).r, imageLoad(u_sumB, v).r);
        value = vec4(sum / (kFixedScale * float(n)), 1.0);
        vec3 a = vec3(imageLoad(u_albedoR, v).r, imageLoad(u_albedoG, v).r, imageLoad(u_albedoB, v).r);
        albedo = vec4(a / (kUnitScale * float(n)), 1.0);
        vec3 m = vec3(imageLoad(u_normalX, v).r, imageLoad(u_normalY, v).r, imageLoad(u_normalZ, v).r);
        normal = vec4(m / (kUnitScale * float(n)), 1.0);
    }
    imageStore(u_radiance, v, value);
    imageStore(u_albedo, v, albedo);
    imageStore(u_normal, v, normal);
}
