#version 450 core
// fire_cover, after fire_cover.comp: level 0 of `fire`, the particles' optical depth
// across each voxel, from its fixed-point sums, for its mips (fire_mip.comp) and the
// lamp's transmittance grid (fire_transmittance.comp) that resolve.comp reads.
layout(local_size_x = 4, local_size_y = 4, local_size_z = 4) in;

#include "sums.glsl"
layout(r16f, binding = 1) uniform writeonly image3D u_fire;

void main() {
    ivec3 v = ivec3(gl_GlobalInvocationID);
    if (any(greaterThanEqual(v, imageSize(u_fire)))) return;
    imageStore(u_fire, v, vec4(float(loadSum(v, kFireCover)) / kCoverScale));
}
