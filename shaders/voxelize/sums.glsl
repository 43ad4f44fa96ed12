// The voxelization's accumulators (passes/voxelize/voxelize.cpp, step 3): fixed-point
// radiance sums and a fragment count per voxel, added to atomically by the rasterized
// fragments (voxelize.frag) and the splatted particles (splat.comp), and the fire's
// cover (fire_cover.comp); resolve.comp
// (which includes this file for the same layout and scales) divides them. Surfaces (not the particles, which only emit) also add their albedo and
// normal: what voxel_mip's bounces reflect, and towards where.
// All in one R32UI volume, grids side by side along x (its width is the grid's
// side times voxelize.cpp's kSumChannels): one image unit where ten would pass OpenGL
// 4.5's guaranteed 8 (NVIDIA's limit, and its fragment shaders' too). The normal's sums
// are signed: two's-complement adds wrap alike in a uint.
layout(r32ui, binding = 0) uniform coherent uimage3D u_sums;
const int kSumR = 0, kSumG = 1, kSumB = 2, kCount = 3, kAlbedoR = 4, kAlbedoG = 5, kAlbedoB = 6, kNormalX = 7,
          kNormalY = 8, kNormalZ = 9, kFireCover = 10, kEmitR = 11, kEmitG = 12, kEmitB = 13;

// Voxel v's texel of one channel (the grid's width: the image's over the channels).
ivec3 sumTexel(ivec3 v, int channel) { return ivec3(v.x + channel * (imageSize(u_sums).x / (kEmitB + 1)), v.yz); }
void addToSum(ivec3 v, int channel, uint value) { imageAtomicAdd(u_sums, sumTexel(v, channel), value); }
uint loadSum(ivec3 v, int channel) { return imageLoad(u_sums, sumTexel(v, channel)).r; }

const float kFixedScale = 512.0;
const float kMaxRadiance = 2048.0;
const float kUnitScale = 4096.0;   // albedo and normal components (|x| ≤ 1): 2^19 fragments a voxel before overflow
const float kCoverScale = 4096.0;  // the fire's optical depth across a voxel: up to 2^20 (a particle adds about 0.36)

uvec3 toFixedRadiance(vec3 radiance) { return uvec3(clamp(radiance, 0.0, kMaxRadiance) * kFixedScale + 0.5); }

// With KILN_FIRE_THROUGH (voxelize's fire_cover on) a fragment's lamp light (kSumR/G/B)
// and its emission (kEmitR/G/B) are summed apart: resolve.comp takes the lamp's part
// through the fire; without it, both into kSumR/G/B.

// One emitting fragment with no surface (a particle), radiance from toFixedRadiance.
void addToVoxel(ivec3 v, uvec3 emitted) {
#if KILN_FIRE_THROUGH
    addToSum(v, kEmitR, emitted.r);
    addToSum(v, kEmitG, emitted.g);
    addToSum(v, kEmitB, emitted.b);
#else
    addToSum(v, kSumR, emitted.r);
    addToSum(v, kSumG, emitted.g);
    addToSum(v, kSumB, emitted.b);
#endif
    addToSum(v, kCount, 1u);
}

// A surface fragment: the lamp light it reflects and what it emits, its albedo and unit
// normal.
void addSurfaceToVoxel(ivec3 v, uvec3 lit, uvec3 emitted, vec3 albedo, vec3 n) {
#if KILN_FIRE_THROUGH
    addToSum(v, kSumR, lit.r);
    addToSum(v, kSumG, lit.g);
    addToSum(v, kSumB, lit.b);
    addToVoxel(v, emitted);
#else
    addToVoxel(v, lit + emitted);
#endif
    uvec3 a = uvec3(clamp(albedo, 0.0, 1.0) * kUnitScale + 0.5);
    ivec3 d = ivec3(round(clamp(n, -1.0, 1.0) * kUnitScale));
    addToSum(v, kAlbedoR, a.r);
    addToSum(v, kAlbedoG, a.g);
    addToSum(v, kAlbedoB, a.b);
    addToSum(v, kNormalX, uint(d.x));
    addToSum(v, kNormalY, uint(d.y));
    addToSum(v, kNormalZ, uint(d.z));
}
