// Sampling the mipped voxel radiance (passes/voxel_mip): quadrilinear lookups (trilinear
// inside a level, linear between levels) of premultiplied colour + opacity over the
// box [-1,1]³. With KILN_HAS_ANISO the cone direction picks three of the six
// directional chains by sign arithmetic, weighted by d² (three fetches, one sampler);
// below level 1 it blends in the isotropic base (level 0 has no directions).
//
// Needs: u_voxels (iso chain, level 0 = voxelize.radiance), u_aniso (the octant
// atlas), u_voxelRes (voxels per side at level 0).
layout(binding = 2) uniform sampler3D u_voxels;
layout(binding = 3) uniform sampler3D u_aniso;
uniform float u_voxelRes;

// p01: position in [0,1]³; d: unit direction of travel; lod: level in base voxels
// (0 = res, 1 = res/2, ...). Uniform-per-step lod keeps the branch below coherent.
vec4 sampleVoxels(vec3 p01, vec3 d, float lod) {
#if KILN_HAS_ANISO
    vec4 base = vec4(0.0);
    if (lod < 1.0) base = textureLod(u_voxels, p01, 0.0);
    if (lod <= 0.0) return base;
    float al = max(lod - 1.0, 0.0);                       // atlas level
    float octTexels = max(0.5 * u_voxelRes / exp2(ceil(al)), 1.0);  // octant side at the coarser level used
    vec3 q = clamp(p01, vec3(0.5 / octTexels), vec3(1.0 - 0.5 / octTexels));
    vec3 neg = vec3(lessThan(d, vec3(0.0)));
    vec3 w = d * d;
    vec4 s = w.x * textureLod(u_aniso, (vec3(neg.x, 0.0, 0.0) + q) * 0.5, al)
           + w.y * textureLod(u_aniso, (vec3(neg.y, 1.0, 0.0) + q) * 0.5, al)
           + w.z * textureLod(u_aniso, (vec3(neg.z, 0.0, 1.0) + q) * 0.5, al);
    return lod < 1.0 ? mix(base, s, lod) : s;
#else
    return textureLod(u_voxels, p01, lod);
#endif
}
