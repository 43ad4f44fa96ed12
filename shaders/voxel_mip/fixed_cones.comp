#version 450 core
// One level of the fixed-cone chains: for each direction d of common/fixed_cones.glsl,
// the anisotropic value a cone along d reads (shaders/cone_trace/voxels.glsl: the three
// directional chains facing d, weighted by d²), blended here once per voxel instead
// of once per cone step. Trilinear filtering is linear, so a lookup into this chain
// equals the three-fetch lookup it replaces (to half-float rounding).
#include "common/fixed_cones.glsl"

layout(local_size_x = 4, local_size_y = 4, local_size_z = 4) in;
layout(rgba16f, binding = 0) uniform readonly image3D u_aniso;   // atlas level: 6 octants of side u_size
layout(rgba16f, binding = 1) uniform writeonly image3D u_fixed;  // same level: kFixedConeTiles tiles along x

uniform int u_size;  // voxels per side of one direction at this level

ivec3 octant(int i) { return ivec3(i & 1, (i >> 1) & 1, i >> 2); }

void main() {
    ivec3 v = ivec3(gl_GlobalInvocationID);
    if (any(greaterThanEqual(v, ivec3(u_size)))) return;
    // Direction i ∈ {+x,−x,+y,−y,+z,−z} lives in octant i (voxel_mip/aniso.comp).
    vec4 face[6];
    for (int i = 0; i < 6; ++i) face[i] = imageLoad(u_aniso, v + octant(i) * u_size);
    for (int t = 0; t < kFixedConeTiles; ++t) {
        vec3 d = fixedConeDirection(t);
        vec3 w = d * d;
        vec4 r = w.x * face[d.x < 0.0 ? 1 : 0] + w.y * face[d.y < 0.0 ? 3 : 2] + w.z * face[d.z < 0.0 ? 5 : 4];
        imageStore(u_fixed, v + ivec3(t * u_size, 0, 0), r);
    }
}
