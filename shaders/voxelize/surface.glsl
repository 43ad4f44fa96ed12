// How a voxelized surface point is lit, shared by the rasterized fragments
// (voxelize.frag) and the splatted spheres (splat.comp): the lamp's diffuse light
// (common/light.glsl) with one hard shadow-map test, taken one voxel off the surface
// along its normal (against acne). Emission is the caller's to add.
// Needs common/light.glsl and common/shadow.glsl; binds the shadow map at texture unit 0
// and, with KILN_LAMP_FIELD, the lamp's field (common/lamp_field.comp) at unit 1. The
// fire between a surface and the lamp is resolve.comp's to take (KILN_FIRE_THROUGH).
layout(binding = 0) uniform sampler2D u_shadowMap;
#if KILN_LAMP_FIELD
#include "common/lamp_field.glsl"
layout(binding = 1) uniform sampler2D u_lampField;
#endif
uniform int u_res;          // voxels along the grid's longest side
uniform ivec3 u_grid;       // voxels per axis
uniform float u_shadowBias;
uniform bool u_unshadowed;  // the lamp dome (voxelize.cpp): the emitter, never in a shadow

// The lamp's irradiance at p, unshadowed: it changes only with the lamp (voxelize keeps
// it with the walls' fragments, static_surfaces.glsl).
vec3 lampIrradiance(vec3 p, vec3 n) {
#if KILN_LAMP_FIELD
    return u_lightColor.rgb * lampFieldSolidAngle(lampFieldAt(u_lampField, p), p, n);
#else
    return lampLight(p, n);
#endif
}

// The fraction of the lamp's light that reaches p: one hard shadow-map test.
float lampVisibility(vec3 p, vec3 n) {
    float vis = 1.0;
#if KILN_HAS_SHADOW_MAP
    vis = u_unshadowed ? 1.0 : shadowHard(u_shadowMap, p + n * kilnVoxelSize(float(u_res)), u_shadowBias);
#endif
    return vis;
}

// Lit from a known irradiance (the one formula, so a kept irradiance gives the same sums).
vec3 lampReflected(vec3 albedo, vec3 irradiance, float vis) { return albedo / 3.14159265 * irradiance * vis; }

vec3 lampReflected(vec3 albedo, vec3 p, vec3 n) { return lampReflected(albedo, lampIrradiance(p, n), lampVisibility(p, n)); }

// A sphere of radius r voxelized on voxels of side h (rasterized conservatively, or
// splatted into the voxels its surface passes through) presents about (2r + h)² to a
// cone where the sphere presents πr²: at its full radiance the blob would carry several
// times the sphere's flux (0.34 of it is right for a 6 cm fireball at 32³). The factor
// that gives the blob the sphere's flux.
float sphereFluxScale(float r) {
    float h = kilnVoxelSize(float(u_res));
    return min(1.0, 3.14159265 * r * r / ((2.0 * r + h) * (2.0 * r + h)));
}
