// The voxelization's accumulators (passes/voxelize/voxelize.cpp, step 3): fixed-point
// radiance sums and a fragment count per voxel, added to atomically by the rasterized
// fragments (voxelize.frag) and the splatted particles (splat.comp); resolve.comp
// (which includes this file for the same layout and scales) divides them. Surfaces (not the particles, which only emit) also add their albedo and
// normal: what voxel_mip's bounces reflect, and towards where.
layout(r32ui, binding = 0) uniform coherent uimage3D u_sumR;
layout(r32ui, binding = 1) uniform coherent uimage3D u_sumG;
layout(r32ui, binding = 2) uniform coherent uimage3D u_sumB;
layout(r32ui, binding = 3) uniform coherent uimage3D u_count;
layout(r32ui, binding = 4) uniform coherent uimage3D u_albedoR;
layout(r32ui, binding = 5) uniform coherent uimage3D u_albedoG;
layout(r32ui, binding = 6) uniform coherent uimage3D u_albedoB;
layout(r32i, binding = 7) uniform coherent iimage3D u_normalX;
layout(r32i, binding = 8) uniform coherent iimage3D u_normalY;
layout(r32i, binding = 9) uniform coherent iimage3D u_normalZ;

const float kFixedScale = 512.0;
const float kMaxRadiance = 2048.0;
const float kUnitScale = 4096.0;   // albedo and normal components (|x| ≤ 1): 2^19 fragments a voxel before overflow

uvec3 toFixedRadiance(vec3 radiance) { return uvec3(clamp(radiance, 0.0, kMaxRadiance) * kFixedScale + 0.5); }

// One fragment's radiance (toFixedRadiance) added to voxel v.
void addToVoxel(ivec3 v, uvec3 fixedRgb) {
    imageAtomicAdd(u_sumR, v, fixedRgb.r);
    imageAtomicAdd(u_sumG, v, fixedRgb.g);
    imageAtomicAdd(u_sumB, v, fixedRgb.b);
    imageAtomicAdd(u_count, v, 1u);
}

// A surface fragment: its radiance, and its albedo and unit normal.
void addSurfaceToVoxel(ivec3 v, uvec3 fixedRgb, vec3 albedo, vec3 n) {
    addToVoxel(v, fixedRgb);
    uvec3 a = uvec3(clamp(albedo, 0.0, 1.0) * kUnitScale + 0.5);
    ivec3 d = ivec3(round(clamp(n, -1.0, 1.0) * kUnitScale));
    imageAtomicAdd(u_albedoR, v, a.r);
    imageAtomicAdd(u_albedoG, v, a.g);
    imageAtomicAdd(u_albedoB, v, a.b);
    imageAtomicAdd(u_normalX, v, d.x);
    imageAtomicAdd(u_normalY, v, d.y);
    imageAtomicAdd(u_normalZ, v, d.z);
}
