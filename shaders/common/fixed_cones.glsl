// The fixed diffuse cone set: the 12 vertices of an icosahedron, as 6 antipodal pairs
// ±kFixedConePairs[j]. Any surface's hemisphere holds one of each pair (the one with
// n·d > 0), so every pixel traces at most 6 cones, weighted by n·d; on the box's walls
// (axis-aligned normals) two pairs lie in the surface's plane and only 4 are traced.
// Being the same for every pixel, each direction's anisotropic lookup can be blended
// once per frame (voxel_mip mode fixed_cones) instead of three fetches per step.
//
// Direction ±kFixedConePairs[j] is tile 2j (+) or 2j+1 (−) of voxel_mip.fixed_cones:
// kFixedConeTiles cubes side by side along x.
const int kFixedConePairs = 6;
const int kFixedConeTiles = 2 * kFixedConePairs;
// (0, ±1, ±φ), (±1, ±φ, 0), (±φ, 0, ±1) / √(1 + φ²), one of each antipodal pair.
const float kIcoA = 0.52573111;  // 1 / √(1 + φ²)
const float kIcoB = 0.85065081;  // φ / √(1 + φ²)
const vec3 kFixedCone[kFixedConePairs] = vec3[](
    vec3(0.0, kIcoA, kIcoB), vec3(0.0, kIcoA, -kIcoB),
    vec3(kIcoA, kIcoB, 0.0), vec3(-kIcoA, kIcoB, 0.0),
    vec3(kIcoB, 0.0, kIcoA), vec3(kIcoB, 0.0, -kIcoA));

// The unit direction of tile t.
vec3 fixedConeDirection(int t) { return (t & 1) == 0 ? kFixedCone[t >> 1] : -kFixedCone[t >> 1]; }
