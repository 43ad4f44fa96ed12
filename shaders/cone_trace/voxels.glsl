// Sampling the mipped voxel radiance (passes/voxel_mip): quadrilinear lookups (trilinear
// inside a level, linear between levels) of premultiplied colour + opacity over the
// voxel volume ([-1,1]³ in volume space, common/frame.glsl). Below level 1 every mode
// blends in the isotropic base (level 0 has no directions). From level 1:
//   KILN_HAS_FIXED_CONES  the cone is direction `tile` of the fixed set: one fetch from
//                         voxel_mip.fixed_cones (the directional chains pre-blended).
//   KILN_HAS_ANISO        the direction d picks three of the six directional chains by
//                         sign arithmetic, weighted by d² (three fetches, one sampler).
//   neither               the isotropic chain.
//
// Needs: u_voxels (iso chain, level 0 = voxelize.radiance), u_aniso (the octant atlas)
// or u_fixedCones (the tile strip), u_voxelDims (voxels per axis at level 0). The
// directional chains end where the grid's shortest axis is one octant voxel across: a
// wider cone reads their top level.
//
// Past a face of the box, a lookup reads what the face holds: a wall (in the outermost
// voxels) goes on as a wall, so a cone that reaches it stops there whatever its width;
// an open face (the Cornell box's front) has nothing behind it. Clamping alone stretched
// the open front's rims — the floor's, the ceiling's and the side walls' last voxels —
// into a tunnel in front of the box: every cone that left by the front met it, and the
// gathered light came out well above the path tracer's, in a box of emitting walls and
// for the lamp's first bounce alike (tests/gi/test_bounces.cpp).
#include "common/frame.glsl"
layout(binding = 2) uniform sampler3D u_voxels;
layout(binding = 3) uniform sampler3D u_aniso;
layout(binding = 6) uniform sampler3D u_fixedCones;
uniform float u_voxelRes;   // voxels along the longest axis (the cone schedule's unit)
uniform vec3 u_voxelDims;   // voxels per axis

#if KILN_HAS_FIXED_CONES
#include "common/fixed_cones.glsl"
#endif

// Clamped half a texel inside one directional block (an octant or a tile) whose side at
// level 1 is res/2, at atlas level al: a lookup never blends in its neighbour.
vec3 insideBlock(vec3 p01, float al) {
    vec3 side = max(0.5 * u_voxelDims / exp2(ceil(al)), vec3(1.0));  // the coarser level used
    return clamp(p01, 0.5 / side, 1.0 - 0.5 / side);
}

// The directional chains' top atlas level (passes/voxel_mip: the shortest axis's octant
// one voxel across).
float atlasTop() { return log2(min(u_voxelDims.x, min(u_voxelDims.y, u_voxelDims.z))) - 1.0; }

// The share of a lookup at p01 on a level of `side` texels per axis that lies inside the
// box or behind a wall: trilinear filtering with an empty border on the open faces.
float insideBox(vec3 p01, vec3 side) {
    uint walls = u_closedFaces.x;
    vec3 wallBelow = vec3(uvec3(walls, walls >> 2, walls >> 4) & 1u);
    vec3 wallAbove = vec3(uvec3(walls >> 1, walls >> 3, walls >> 5) & 1u);
    vec3 below = max(clamp(p01 * side + 0.5, 0.0, 1.0), wallBelow);
    vec3 above = max(clamp(side - p01 * side + 0.5, 0.0, 1.0), wallAbove);
    vec3 f = below * above;
    return f.x * f.y * f.z;
}

// p01: position in [0,1]³; d: unit direction of travel; tile: its index in the fixed
// set (KILN_HAS_FIXED_CONES only); lod: level in base voxels (0 = res, 1 = res/2, ...).
// Uniform-per-step lod keeps the branches below coherent.
vec4 sampleVoxels(vec3 p01, vec3 d, int tile, float lod) {
#if KILN_HAS_ANISO || KILN_HAS_FIXED_CONES
    vec4 base = vec4(0.0);
    if (lod < 1.0) base = textureLod(u_voxels, p01, 0.0) * insideBox(p01, u_voxelDims);
    if (lod <= 0.0) return base;
    float al = clamp(lod - 1.0, 0.0, atlasTop());  // atlas level
    vec3 q = insideBlock(p01, al);
    float inside = insideBox(p01, max(0.5 * u_voxelDims / exp2(al), vec3(1.0)));
#if KILN_HAS_FIXED_CONES
    vec4 s = textureLod(u_fixedCones, vec3((float(tile) + q.x) / float(kFixedConeTiles), q.y, q.z), al) * inside;
#else
    vec3 neg = vec3(lessThan(d, vec3(0.0)));
    vec3 w = d * d;
    vec4 s = w.x * textureLod(u_aniso, (vec3(neg.x, 0.0, 0.0) + q) * 0.5, al)
           + w.y * textureLod(u_aniso, (vec3(neg.y, 1.0, 0.0) + q) * 0.5, al)
           + w.z * textureLod(u_aniso, (vec3(neg.z, 0.0, 1.0) + q) * 0.5, al);
    s *= inside;
#endif
    return lod < 1.0 ? mix(base, s, lod) : s;
#else
    return textureLod(u_voxels, p01, lod) * insideBox(p01, max(u_voxelDims / exp2(lod), vec3(1.0)));
#endif
}
