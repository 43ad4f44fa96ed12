#version 450 core
// Anisotropic mip level (Crassin et al. 2011), all six directions of one parent voxel
// per invocation. Direction i ∈ {+x,−x,+y,−y,+z,−z}; its chain lives in the octant
// (i&1, (i>>1)&1, i>>2) of the atlas (passes/voxel_mip/voxel_mip.cpp). The value for
// direction D = the mean over the 4 child pairs along D's axis of the front-to-back
// composite (front = the child met first travelling along D).
layout(local_size_x = 4, local_size_y = 4, local_size_z = 4) in;
layout(rgba16f, binding = 0) uniform readonly image3D u_src;   // the iso level 0, or the previous atlas level
layout(rgba16f, binding = 1) uniform writeonly image3D u_dst;  // atlas level (octant side u_size)

layout(binding = 2) uniform sampler3D u_normal;                // voxelize.normal (u_facing only)
#if KILN_ANISO_FIXED_CONES
// voxel_mip fixed_cones: the same level of the fixed-cone chains (common/fixed_cones.glsl),
// blended from the six values here: for each direction d, the three facing it weighted
// by d² (a lookup into it equals the three-lookup blend cone_trace/voxels.glsl does
// otherwise: trilinear filtering is linear). In the same dispatch: a dispatch of its own
// reloaded the six and cost llvmpipe time at every level before any work.
#include "common/fixed_cones.glsl"
layout(rgba16f, binding = 3) uniform writeonly image3D u_fixed;  // kFixedConeTiles tiles of side u_size along x
#endif

// KILN_ANISO_FROM_BASE 1: the source is the isotropic base (the same for every
// direction), 0: the previous atlas level. KILN_ANISO_FACING (from the base only) 0: off;
// 1: back faces empty; 2: back faces and edge-on empty. Defines, not uniforms: llvmpipe
// runs every side of a branch, and the three ways of building a level (8, 8 + 8 and 48
// loads) all ran for every voxel.
#ifndef KILN_ANISO_FROM_BASE
#define KILN_ANISO_FROM_BASE 0
#endif
#ifndef KILN_ANISO_FACING
#define KILN_ANISO_FACING 0
#endif
uniform ivec3 u_size;    // parent voxels per axis at this level (an octant's)

ivec3 octant(int i) { return ivec3(i & 1, (i >> 1) & 1, i >> 2); }

vec4 over(vec4 front, vec4 back) { return front + (1.0 - front.a) * back; }

// Children c<xyz> named by their offset bits. Pairs along x: (c000,c100), (c010,c110),
// (c001,c101), (c011,c111); likewise for y and z. Written out (no arrays, no dynamic
// indexing), which llvmpipe compiles to straight vector code.
#define LOAD8(src, b)                                                          \
    vec4 c000 = imageLoad(src, b), c100 = imageLoad(src, b + ivec3(1, 0, 0)), \
         c010 = imageLoad(src, b + ivec3(0, 1, 0)), c110 = imageLoad(src, b + ivec3(1, 1, 0)), \
         c001 = imageLoad(src, b + ivec3(0, 0, 1)), c101 = imageLoad(src, b + ivec3(1, 0, 1)), \
         c011 = imageLoad(src, b + ivec3(0, 1, 1)), c111 = imageLoad(src, b + ivec3(1, 1, 1))

// The value for direction i from its 8 children.
vec4 directional(int i, vec4 c000, vec4 c100, vec4 c010, vec4 c110, vec4 c001, vec4 c101, vec4 c011, vec4 c111) {
    vec4 r;
    if (i == 0) r = over(c000, c100) + over(c010, c110) + over(c001, c101) + over(c011, c111);
    else if (i == 1) r = over(c100, c000) + over(c110, c010) + over(c101, c001) + over(c111, c011);
    else if (i == 2) r = over(c000, c010) + over(c100, c110) + over(c001, c011) + over(c101, c111);
    else if (i == 3) r = over(c010, c000) + over(c110, c100) + over(c011, c001) + over(c111, c101);
    else if (i == 4) r = over(c000, c001) + over(c100, c101) + over(c010, c011) + over(c110, c111);
    else r = over(c001, c000) + over(c101, c100) + over(c011, c010) + over(c111, c110);
    return r * 0.25;
}

const vec3 kDirection[6] = vec3[](vec3(1, 0, 0), vec3(-1, 0, 0), vec3(0, 1, 0), vec3(0, -1, 0), vec3(0, 0, 1), vec3(0, 0, -1));

// What of a base voxel a cone travelling along d meets (u_facing > 0). A surface
// voxel seen from behind (its mean normal m along d: the cone leaves that surface, as
// every cone leaves its own) is empty, light and opacity both: rays from outside a
// closed surface never meet its back. u_facing 2 empties it edge-on too (|m̂·d| < 0.05:
// a thin plane's projected area is zero, so a cone running along a wall does not meet
// it — nor does one that meets the wall obliquely, through this axis's share of the
// blend, hence a knob). |m| < 1 (surfaces facing several ways in one voxel) blends
// towards keeping it whole.
vec4 facing(vec4 c, vec3 m, vec3 d) {
    float f = min(length(m), 1.0);
    if (f < 1e-3) return c;
#if KILN_ANISO_FACING == 2
    float front = 1.0 - step(-0.05 * f, dot(m, d));  // edge-on emptied too
#else
    float front = step(dot(m, d), 0.0);  // edge-on (m·d = 0) kept
#endif
    return c * ((1.0 - f) + f * front);
}

void main() {
    ivec3 v = ivec3(gl_GlobalInvocationID);
    if (any(greaterThanEqual(v, u_size))) return;
    vec4 face[6];
#if KILN_ANISO_FROM_BASE && KILN_ANISO_FACING > 0
    {
        ivec3 b = 2 * v;
        LOAD8(u_src, b);
        vec3 m000 = texelFetch(u_normal, b, 0).xyz, m100 = texelFetch(u_normal, b + ivec3(1, 0, 0), 0).xyz,
             m010 = texelFetch(u_normal, b + ivec3(0, 1, 0), 0).xyz, m110 = texelFetch(u_normal, b + ivec3(1, 1, 0), 0).xyz,
             m001 = texelFetch(u_normal, b + ivec3(0, 0, 1), 0).xyz, m101 = texelFetch(u_normal, b + ivec3(1, 0, 1), 0).xyz,
             m011 = texelFetch(u_normal, b + ivec3(0, 1, 1), 0).xyz, m111 = texelFetch(u_normal, b + ivec3(1, 1, 1), 0).xyz;
        for (int i = 0; i < 6; ++i) {
            vec3 d = kDirection[i];
            face[i] = directional(i, facing(c000, m000, d), facing(c100, m100, d), facing(c010, m010, d),
                                  facing(c110, m110, d), facing(c001, m001, d), facing(c101, m101, d),
                                  facing(c011, m011, d), facing(c111, m111, d));
        }
    }
#elif KILN_ANISO_FROM_BASE
    {
        LOAD8(u_src, 2 * v);
        for (int i = 0; i < 6; ++i) face[i] = directional(i, c000, c100, c010, c110, c001, c101, c011, c111);
    }
#else
    for (int i = 0; i < 6; ++i) {
        LOAD8(u_src, 2 * v + octant(i) * (2 * u_size));
        face[i] = directional(i, c000, c100, c010, c110, c001, c101, c011, c111);
    }
#endif
    for (int i = 0; i < 6; ++i) imageStore(u_dst, v + octant(i) * u_size, face[i]);
#if KILN_ANISO_FIXED_CONES
    for (int t = 0; t < kFixedConeTiles; ++t) {
        vec3 d = fixedConeDirection(t);
        vec3 w = d * d;
        vec4 r = w.x * face[d.x < 0.0 ? 1 : 0] + w.y * face[d.y < 0.0 ? 3 : 2] + w.z * face[d.z < 0.0 ? 5 : 4];
        imageStore(u_fixed, v + ivec3(t * u_size.x, 0, 0), r);
    }
#endif
}
