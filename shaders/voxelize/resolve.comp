#version 450 core
// Voxelization, stage 4: mean radiance = fixed-point sum / count; occupancy in alpha.
// Colour premultiplied by occupancy (empty voxels are all zero). The surfaces' mean
// albedo and mean normal over the same count: a voxel that also holds particles (which
// reflect nothing) reflects that much less, as its mean radiance is that much more
// emission.
layout(local_size_x = 4, local_size_y = 4, local_size_z = 4) in;

#include "sums.glsl"  // the accumulators (image unit 0) and their fixed-point scales
layout(rgba16f, binding = 1) uniform writeonly image3D u_radiance;
layout(rgba8, binding = 2) uniform writeonly image3D u_albedo;
layout(rgba16f, binding = 3) uniform writeonly image3D u_normal;
#if KILN_FIRE_THROUGH
// The lamp's part of each voxel's light through the fire (fireballs and particles)
// between it and the lamp (fire_transmittance.comp), as cone_trace takes it for the
// pixels.
layout(binding = 0) uniform sampler3D u_lampTransmittance;
#endif

void main() {
    ivec3 v = ivec3(gl_GlobalInvocationID);
    if (any(greaterThanEqual(v, imageSize(u_radiance)))) return;
    uint n = loadSum(v, kCount);
    vec4 value = vec4(0.0), albedo = vec4(0.0), normal = vec4(0.0);
    if (n > 0u) {
        vec3 sum = vec3(loadSum(v, kSumR), loadSum(v, kSumG), loadSum(v, kSumB));
        vec3 a = vec3(loadSum(v, kAlbedoR), loadSum(v, kAlbedoG), loadSum(v, kAlbedoB));
        albedo = vec4(a / (kUnitScale * float(n)), 1.0);
        vec3 m = vec3(int(loadSum(v, kNormalX)), int(loadSum(v, kNormalY)), int(loadSum(v, kNormalZ)));
        normal = vec4(m / (kUnitScale * float(n)), 1.0);
#if KILN_FIRE_THROUGH
        sum *= textureLod(u_lampTransmittance, (vec3(v) + 0.5) / vec3(imageSize(u_radiance)), 0.0).r;
        sum += vec3(loadSum(v, kEmitR), loadSum(v, kEmitG), loadSum(v, kEmitB));
#endif
        value = vec4(sum / (kFixedScale * float(n)), 1.0);
    }
    imageStore(u_radiance, v, value);
    imageStore(u_albedo, v, albedo);
    imageStore(u_normal, v, normal);
}
