// Diffuse cone tracing through the mipped voxels (shaders/cone_trace/voxels.glsl).
#include "voxels.glsl"

const int kMaxCones = 16;
uniform int u_coneCount;
uniform vec4 u_cones[kMaxCones];  // xyz = direction in the normal's frame (z = normal), w = weight (Σ = 1)
uniform float u_tanHalf;          // tan(aperture / 2)
uniform float u_maxDistance;      // world units
uniform float u_stepMultiplier;   // step = diameter × this
uniform float u_startOffset;      // in level-0 voxels, along the normal

// Front-to-back composite along one cone: rgb = radiance arriving (premultiplied),
// a = opacity met. Steps grow with the cone diameter (at least one voxel of the
// current level), so a cone costs O(log distance) samples.
vec4 traceCone(vec3 origin, vec3 dir) {
    float voxel = 2.0 / u_voxelRes;
    float maxLod = log2(u_voxelRes);
    vec4 acc = vec4(0.0);
    float t = voxel;
    while (t < u_maxDistance && acc.a < 0.97) {
        float diameter = max(voxel, 2.0 * t * u_tanHalf);
        float lod = min(log2(diameter / voxel), maxLod);
        vec3 p = origin + dir * t;
        if (any(greaterThan(abs(p), vec3(1.0)))) break;
        vec4 s = sampleVoxels(p * 0.5 + 0.5, dir, lod);
        // Opacity of a slab `step` long instead of one diameter.
        float a = 1.0 - pow(max(1.0 - s.a, 0.0), u_stepMultiplier);
        s.rgb *= s.a > 1e-4 ? a / s.a : u_stepMultiplier;
        acc.rgb += (1.0 - acc.a) * s.rgb;
        acc.a += (1.0 - acc.a) * a;
        t += diameter * u_stepMultiplier;
    }
    return acc;
}

// Indirect irradiance at p with normal n, as the cosine-weighted mean incoming
// radiance (so outgoing diffuse = albedo × rgb); a = ambient visibility (1 − the
// weighted cone opacity).
vec4 traceDiffuse(vec3 p, vec3 n) {
    vec3 up = abs(n.y) < 0.95 ? vec3(0.0, 1.0, 0.0) : vec3(1.0, 0.0, 0.0);
    vec3 tx = normalize(cross(up, n));
    vec3 ty = cross(n, tx);
    vec3 origin = p + n * (u_startOffset * 2.0 / u_voxelRes);
    vec4 sum = vec4(0.0);
    for (int i = 0; i < u_coneCount; ++i) {
        vec3 d = normalize(u_cones[i].x * tx + u_cones[i].y * ty + u_cones[i].z * n);
        sum += u_cones[i].w * traceCone(origin, d);
    }
    return vec4(sum.rgb, 1.0 - sum.a);
}
