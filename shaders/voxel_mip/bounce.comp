#version 450 core
// voxel_mip, one more bounce (passes/voxel_mip/voxel_mip.cpp): the surfaces in each
// block of KILN_GATHER_BLOCK³ voxels gather the light arriving at them through the
// chains built from the voxels' current radiance — the same cones and marching as the
// pixels (cone_trace/trace.glsl) — and reflect it on top of what voxelize put there
// (direct light and emission):
//     L_k(v) = L_0(v) + albedo(v) · Ē_k−1(block of v),   Ē = cosine-weighted mean radiance = E/π.
// One gather a block (2³: an eighth of the cones) is enough for light that has already
// bounced: it is smooth over a voxel or two.
// The cones: the fixed set's 12 directions (common/fixed_cones.glsl), 60° each, weighted
// by the surfaces' mean normal m as a blend of a cosine lobe (|m| = 1: one flat surface)
// and the whole sphere (|m| = 0: surfaces facing every way, e.g. a ball in the block):
//     w(d) = |m| · max(m̂·d, 0) + (1 − |m|) / 4
// (1/4: the mean of max(n·d, 0) over the sphere), normalised over the cones traced.
// KILN_BOUNCE_STEP: 0 = gather and reflect (the above, into u_bounced); with feedback
// (voxel_mip's `feedback`), 1 = gather only, kept as Ē per voxel for the next frame, and
// 2 = no gather: L = L_0 + albedo · (that kept Ē), the frame's starting level 0; with
// KILN_GATHER_LIST it also lists the blocks that hold a reflecting surface (their indices
// in GatherList, the dispatch size of a 64-wide pass over them beside it) and writes the
// kept gather of every other block: nothing, what step 1 would have gathered there. Step
// 1 with KILN_GATHER_LIST then runs over the list only: llvmpipe runs a compute shader's
// loop for all 8 lanes of a SIMD vector while any one has work, and every row of 8 blocks
// meets a side wall, so over the whole grid every block paid a surface's cones. (The
// list was a dispatch of its own, which read the same voxels again.)
// fixed_cones.glsl first: trace.glsl's voxels.glsl includes it only inside
// `#if KILN_HAS_FIXED_CONES`, and a file is included once per stage.
#include "common/fixed_cones.glsl"
#include "cone_trace/trace.glsl"

#if KILN_GATHER_LIST && KILN_BOUNCE_STEP == 1
layout(local_size_x = 64) in;
#else
layout(local_size_x = 4, local_size_y = 4, local_size_z = 4) in;
#endif
#if KILN_GATHER_LIST
// Filled by step 2, read by step 1; `dispatch` is glDispatchComputeIndirect's (x, y, z).
layout(std430, binding = 2) buffer GatherList {
    uint u_dispatch[3];
    uint u_listed;
    uint u_blocks[];  // x | y << 10 | z << 20
};
#endif
layout(binding = 0) uniform sampler3D u_emitted;  // voxelize.radiance: direct light + emission
layout(binding = 1) uniform sampler3D u_albedo;   // voxelize.albedo
layout(binding = 4) uniform sampler3D u_normal;   // voxelize.normal
layout(binding = 5) uniform sampler3D u_gathered;  // KILN_BOUNCE_STEP 2: the last frame's step 1
layout(rgba16f, binding = 0) uniform writeonly image3D u_bounced;
#if KILN_BOUNCE_STEP == 2 && KILN_GATHER_LIST
// The same texture as u_gathered: each invocation empties only its own block's voxels,
// after reading them.
layout(rgba16f, binding = 1) uniform writeonly image3D u_forgotten;
#endif

const int kBlock = KILN_GATHER_BLOCK;

bool reflects(vec4 radiance, vec3 albedo) { return radiance.a > 0.0 && max(albedo.r, max(albedo.g, albedo.b)) > 0.0; }

// Voxel i (0 … kBlock³ − 1) of a block.
ivec3 voxelOf(ivec3 block, int i) { return block * kBlock + ivec3(i % kBlock, (i / kBlock) % kBlock, i / (kBlock * kBlock)); }

// The weight of cone direction d for surfaces of mean normal direction n and |m| = facing.
float coneWeight(vec3 n, float facing, vec3 d) { return facing * max(dot(n, d), 0.0) + (1.0 - facing) * 0.25; }

// The light gathered at block's surfaces (mean incoming radiance, Ē = E/π).
vec3 gatherBlock(ivec3 block) {
    // The block's surfaces: their mean normal, and where they are.
    vec3 normalSum = vec3(0.0), centreSum = vec3(0.0);
    float surfaces = 0.0;
    for (int i = 0; i < kBlock * kBlock * kBlock; ++i) {
        ivec3 v = voxelOf(block, i);
        if (!reflects(texelFetch(u_emitted, v, 0), texelFetch(u_albedo, v, 0).rgb)) continue;
        normalSum += texelFetch(u_normal, v, 0).xyz;
        centreSum += ((vec3(v) + 0.5) / u_voxelDims * 2.0 - 1.0) * u_voxelExtent.xyz;  // volume space
        surfaces += 1.0;
    }
    if (surfaces == 0.0) return vec3(0.0);
    vec3 m = normalSum / surfaces;
    float facing = min(length(m), 1.0);
    vec3 n = facing > 1e-3 ? normalize(m) : vec3(0.0, 1.0, 0.0);
    vec3 centre = centreSum / surfaces;
    // The cones to trace as a bit mask, walked with findLSB: llvmpipe runs an `if`
    // body for every lane but leaves a loop once no lane has work (a wall's blocks
    // trace 4 cones, not 12).
    uint cones = 0u;
    for (int t = 0; t < kFixedConeTiles; ++t)
        if (coneWeight(n, facing, fixedConeDirection(t)) >= 1e-3) cones |= 1u << t;
    vec3 sum = vec3(0.0);
    float weights = 0.0;
    for (; cones != 0u; cones &= cones - 1u) {
        int t = findLSB(cones);
        vec3 d = fixedConeDirection(t);
        float w = coneWeight(n, facing, d);
        // Off the surfaces: along their normal, or along the cone where they face
        // every way.
        vec3 away = facing >= 0.5 ? n : d;
        sum += w * traceCone(centre + away * (u_startOffset * 2.0 / u_voxelRes), away, d, t).rgb;
        weights += w;
    }
    return sum / max(weights, 1e-6);
}

// Voxel v's radiance as voxelize left it (direct light, emission) plus, where it holds a
// reflecting surface, albedo × the mean radiance arriving at it.
vec4 reflecting(ivec3 v, vec3 incoming) {
    vec4 radiance = texelFetch(u_emitted, v, 0);
    vec3 albedo = texelFetch(u_albedo, v, 0).rgb;
    if (reflects(radiance, albedo)) radiance.rgb += albedo * incoming * radiance.a;
    return radiance;
}

#if KILN_BOUNCE_STEP == 2 && KILN_GATHER_LIST
// Step 1 gathers at `block` (a reflecting surface is in it); or, none being there, what
// it would have gathered is nothing.
void listOrForget(ivec3 block, bool surface) {
    if (surface) {
        uint index = atomicAdd(u_listed, 1u);
        u_blocks[index] = uint(block.x) | uint(block.y) << 10 | uint(block.z) << 20;
        if (index % 64u == 0u) atomicAdd(u_dispatch[0], 1u);  // one more 64-wide group
    } else {
        for (int i = 0; i < kBlock * kBlock * kBlock; ++i)
            imageStore(u_forgotten, voxelOf(block, i), vec4(0.0, 0.0, 0.0, 1.0));
    }
}
#endif

void main() {
#if KILN_GATHER_LIST && KILN_BOUNCE_STEP == 1
    if (gl_GlobalInvocationID.x >= u_listed) return;
    uint code = u_blocks[gl_GlobalInvocationID.x];
    ivec3 block = ivec3(code & 1023u, (code >> 10) & 1023u, code >> 20);
#else
    ivec3 block = ivec3(gl_GlobalInvocationID);
    if (any(greaterThanEqual(block * kBlock, ivec3(u_voxelDims)))) return;
#endif
#if KILN_BOUNCE_STEP != 2
    vec3 gathered = gatherBlock(block);
#endif
#if KILN_BOUNCE_STEP == 2 && KILN_GATHER_LIST
    bool surface = false;
#endif
    for (int i = 0; i < kBlock * kBlock * kBlock; ++i) {
        ivec3 v = voxelOf(block, i);
#if KILN_BOUNCE_STEP == 0
        imageStore(u_bounced, v, reflecting(v, gathered));
#elif KILN_BOUNCE_STEP == 1
        // Kept for the next frame (feedback): the gather itself, reflected there.
        imageStore(u_bounced, v, vec4(gathered, 1.0));
#else
        // The last frame's gather (feedback), reflected: this frame's level 0.
        imageStore(u_bounced, v, reflecting(v, texelFetch(u_gathered, v, 0).rgb));
#if KILN_GATHER_LIST
        surface = surface || reflects(texelFetch(u_emitted, v, 0), texelFetch(u_albedo, v, 0).rgb);
#endif
#endif
    }
#if KILN_BOUNCE_STEP == 2 && KILN_GATHER_LIST
    listOrForget(block, surface);
#endif
}
