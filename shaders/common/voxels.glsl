// Sampling the voxel radiance chains of voxel_mip. `lod` is in base-voxel units:
// 0 = the base resolution, 1 = voxels twice as large, ...
layout(binding = 4) uniform sampler3D u_voxelsIso;
layout(binding = 5) uniform sampler3D u_voxelsAniso;

// Premultiplied radiance (a = occupancy) at world point p for a cone along dir.
vec4 sampleVoxels(vec3 p, vec3 dir, float lod) {
    vec3 uvw = p * 0.5 + 0.5;
#if KILN_HAS_VOXELS_ANISO
    // The atlas starts at half the base resolution (its level 0 = base lod 1).
    float alod = max(lod - 1.0, 0.0);
    float slabSide = float(textureSize(u_voxelsAniso, 0).y);
    alod = min(alod, log2(slabSide));
    float half_ = 0.5 / max(slabSide / exp2(ceil(alod)), 1.0);
    float x = clamp(uvw.x, half_, 1.0 - half_);
    // Slab by sign, chosen with arithmetic: three fetches whatever the direction.
    vec3 sgn = vec3(lessThan(dir, vec3(0.0)));
    vec3 w = dir * dir;
    vec4 sx = textureLod(u_voxelsAniso, vec3((0.0 + sgn.x + x) / 6.0, uvw.yz), alod);
    vec4 sy = textureLod(u_voxelsAniso, vec3((2.0 + sgn.y + x) / 6.0, uvw.yz), alod);
    vec4 sz = textureLod(u_voxelsAniso, vec3((4.0 + sgn.z + x) / 6.0, uvw.yz), alod);
    return w.x * sx + w.y * sy + w.z * sz;
#else
    return textureLod(u_voxelsIso, uvw, lod);
#endif
}

float voxelSize() {
#if KILN_HAS_VOXELS_ANISO
    return 2.0 / (2.0 * float(textureSize(u_voxelsAniso, 0).y));
#else
    return 2.0 / float(textureSize(u_voxelsIso, 0).x);
#endif
}
