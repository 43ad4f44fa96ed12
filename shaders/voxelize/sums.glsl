// The voxelization's accumulators (passes/voxelize/voxelize.cpp, step 3): fixed-point
// radiance sums and a fragment count per voxel, added to atomically by the rasterized
// fragments (voxelize.frag) and the splatted particles (splat.comp); resolve.comp
// divides them.
layout(r32ui, binding = 0) uniform coherent uimage3D u_sumR;
layout(r32ui, binding = 1) uniform coherent uimage3D u_sumG;
layout(r32ui, binding = 2) uniform coherent uimage3D u_sumB;
layout(r32ui, binding = 3) uniform coherent uimage3D u_count;

const float kFixedScale = 512.0;   // keep in sync with resolve.comp
const float kMaxRadiance = 2048.0;

uvec3 toFixedRadiance(vec3 radiance) { return uvec3(clamp(radiance, 0.0, kMaxRadiance) * kFixedScale + 0.5); }

// One fragment's radiance (toFixedRadiance) added to voxel v.
void addToVoxel(ivec3 v, uvec3 fixedRgb) {
    imageAtomicAdd(u_sumR, v, fixedRgb.r);
    imageAtomicAdd(u_sumG, v, fixedRgb.g);
    imageAtomicAdd(u_sumB, v, fixedRgb.b);
    imageAtomicAdd(u_count, v, 1u);
}
