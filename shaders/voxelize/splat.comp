#version 450 core
// Voxelization of the particles without their meshes: one invocation per particle adds
// its emitted radiance, as one fragment would, to every voxel its bounding box
// overlaps (one voxel for a particle smaller than a voxel, at most 2×2×2), into the
// same fixed-point sums and count as voxelize.frag, so resolve.comp averages it with
// the surfaces around it. The particles are the instances [u_first, u_first +
// u_particleCount) of the scene's instance buffer; they are emitters with no albedo,
// so no lamp light and no shadow test. Cost: a few atomics per particle, where
// rasterizing the mesh cost a geometry shader invocation per triangle.
#include "common/instances.glsl"
#include "sums.glsl"

layout(local_size_x = 64) in;

uniform uint u_first;
uniform uint u_particleCount;
uniform int u_res;

void main() {
    if (gl_GlobalInvocationID.x >= u_particleCount) return;
    KilnInstance inst = kiln_instances[u_first + gl_GlobalInvocationID.x];
    vec3 centre = kilnSphereCentre(inst);
    float radius = kilnSphereRadius(inst);
    uvec3 fixedRgb = toFixedRadiance(inst.emissive.rgb);
    // Voxel index range of the bounding box, at most two voxels per axis.
    ivec3 lo = ivec3(floor(((centre - radius) * 0.5 + 0.5) * float(u_res)));
    ivec3 hi = min(ivec3(floor(((centre + radius) * 0.5 + 0.5) * float(u_res))), lo + 1);
    lo = max(lo, ivec3(0));
    hi = min(hi, ivec3(u_res - 1));
    for (int z = lo.z; z <= hi.z; ++z)
        for (int y = lo.y; y <= hi.y; ++y)
            for (int x = lo.x; x <= hi.x; ++x) addToVoxel(ivec3(x, y, z), fixedRgb);
}
