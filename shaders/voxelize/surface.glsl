// How a voxelized surface point is lit, shared by the rasterized fragments
// (voxelize.frag) and the splatted spheres (splat.comp): the lamp's diffuse light
// (common/light.glsl) with one hard shadow-map test, taken one voxel off the surface
// along its normal (against acne). Emission is the caller's to add.
// Needs common/light.glsl; binds the shadow map at texture unit 0.
layout(binding = 0) uniform sampler2D u_shadowMap;
uniform int u_res;          // voxels per side
uniform float u_shadowBias;

vec3 lampReflected(vec3 albedo, vec3 p, vec3 n) {
    float vis = 1.0;
#if KILN_HAS_SHADOW_MAP
    vis = shadowHard(u_shadowMap, p + n * (2.0 / float(u_res)), u_shadowBias);
#endif
    return albedo / 3.14159265 * lampLight(p, n) * vis;
}
