// Diffuse cone tracing through the mipped voxels (shaders/cone_trace/voxels.glsl).
#include "voxels.glsl"

uniform float u_startOffset;      // in level-0 voxels, along the normal
uniform float u_diameterOffset;   // × each sample's diameter, along the normal

// The step schedule, a compile-time constant (passes/cone_trace/cone_trace.cpp):
// per step the distance t, the cone diameter, the mip level and spacing/diameter.
const vec4 kSchedule[KILN_CONE_STEPS] = vec4[](KILN_CONE_SCHEDULE);

// Front-to-back composite along one cone, in volume space (common/frame.glsl: the voxel
// volume as [-e, e], one scale on every axis, where the step schedule is laid out): rgb =
// radiance arriving (premultiplied), a = opacity met. Samples outside the box count as
// empty (the walls sit in the outermost voxels, so nothing is lost).
// tile: the cone's index in the fixed set (KILN_HAS_FIXED_CONES), else unused.
vec4 traceCone(vec3 origin, vec3 n, vec3 dir, int tile) {
    vec4 acc = vec4(0.0);
    for (int i = 0; i < KILN_CONE_STEPS; ++i) {
        // Each sample also moves off the surface by a fraction of its own diameter:
        // a coarse voxel that straddles the surface would otherwise put the surface's
        // own (opaque) voxels into the cone (self-occlusion; in the directional chain
        // along the normal, the wall is in front of everything else).
        vec3 p = origin + n * (u_diameterOffset * kSchedule[i].y) + dir * kSchedule[i].x;
        // No early exit: with the loop unrolled, a branch around the lookups cost more
        // than it saved on llvmpipe (measured).
        vec4 s = sampleVoxels(kilnVolumeToGrid(p) * 0.5 + 0.5, dir, tile, kSchedule[i].z);
        // Past the box (the sample no longer overlaps [-e, e]): nothing there.
        s *= all(lessThanEqual(abs(p), u_voxelExtent.xyz + 0.5 * kSchedule[i].y)) ? 1.0 : 0.0;
        // Opacity of a slab `spacing` long instead of one diameter.
        float a = 1.0 - pow(max(1.0 - s.a, 1e-6), kSchedule[i].w);
        s.rgb *= a / max(s.a, 1e-6);
        acc.rgb += (1.0 - acc.a) * s.rgb;
        acc.a += (1.0 - acc.a) * a;
    }
    return acc;
}

// Indirect irradiance at world point p with normal n, as the cosine-weighted mean incoming
// radiance (so outgoing diffuse = albedo × rgb); a = ambient visibility (1 − the
// weighted cone opacity).
#if KILN_HAS_FIXED_CONES
// The fixed set (common/fixed_cones.glsl): of each antipodal pair the member with
// n·d > 0, weighted by n·d and normalised over the cones traced. Pairs that lie in
// the surface's plane (|n·d| < kMinCosine: two pairs on every wall of the box) are
// skipped: a loop over a bit mask, because llvmpipe runs an `if` body for every lane
// but leaves a loop once no lane has work.
const float kMinCosine = 0.05;

vec4 traceDiffuse(vec3 p, vec3 n) {
    vec3 origin = kilnWorldToVolume(p) + n * (u_startOffset * 2.0 / u_voxelRes);
    uint pairs = 0u;
    for (int j = 0; j < kFixedConePairs; ++j)
        if (abs(dot(n, kFixedCone[j])) >= kMinCosine) pairs |= 1u << j;
    vec4 sum = vec4(0.0);
    float weights = 0.0;
    for (; pairs != 0u; pairs &= pairs - 1u) {
        int j = findLSB(pairs);
        float c = dot(n, kFixedCone[j]);
        int tile = 2 * j + (c < 0.0 ? 1 : 0);
        sum += abs(c) * traceCone(origin, n, sign(c) * kFixedCone[j], tile);
        weights += abs(c);
    }
    sum /= max(weights, 1e-6);
    return vec4(sum.rgb, 1.0 - sum.a);
}
#else
// The cone set around the normal (passes/cone_trace/cone_trace.cpp coneSet).
const int kMaxCones = 16;
uniform int u_coneCount;
uniform vec4 u_cones[kMaxCones];  // xyz = direction in the normal's frame (z = normal), w = weight (Σ = 1)

vec4 traceDiffuse(vec3 p, vec3 n) {
    vec3 up = abs(n.y) < 0.95 ? vec3(0.0, 1.0, 0.0) : vec3(1.0, 0.0, 0.0);
    vec3 tx = normalize(cross(up, n));
    vec3 ty = cross(n, tx);
    vec3 origin = kilnWorldToVolume(p) + n * (u_startOffset * 2.0 / u_voxelRes);
    vec4 sum = vec4(0.0);
    for (int i = 0; i < u_coneCount; ++i) {
        vec3 d = normalize(u_cones[i].x * tx + u_cones[i].y * ty + u_cones[i].z * n);
        sum += u_cones[i].w * traceCone(origin, n, d, 0);
    }
    return vec4(sum.rgb, 1.0 - sum.a);
}
#endif
