#version 450 core
// Voxelization of spheres without their meshes: one invocation per sphere adds one
// fragment's radiance to every voxel the sphere's surface passes through (the voxel's
// nearest point within the radius of the centre, its farthest corner beyond it), into
// the same fixed-point sums and count as voxelize.frag, so resolve.comp averages it with
// the surfaces around it. A sphere smaller than a voxel lands in the voxels its bounding
// box overlaps (at most 2×2×2).
//   KILN_SPLAT_LIT 1, fireballs: emission (scaled as the rasterized ones:
//              fireball_emission, and with fireball_flux to the sphere's flux) plus the
//              lamp's light on the surface point facing the voxel's centre, lit as
//              voxelize.frag lights a fragment (surface.glsl).
//   KILN_SPLAT_LIT 0, particles: emitters with no albedo: their emission, no surface
//              (albedo, normal).
// The spheres are the instances [u_first, u_first + u_sphereCount) of the scene's
// instance buffer. Cost: a few atomics per voxel of the shell, where rasterizing the mesh cost a
// geometry-shader invocation per triangle.
#include "common/frame.glsl"
#include "common/instances.glsl"
#include "common/light.glsl"
#include "common/shadow.glsl"
#include "sums.glsl"
#include "surface.glsl"

layout(local_size_x = KILN_SPLAT_GROUP) in;  // voxelize.cpp: as it dispatches

uniform uint u_first;
uniform uint u_sphereCount;
uniform float u_fireballEmission;  // voxelize's fireball_emission, as the rasterized fireballs take it
uniform bool u_sphereFlux;         // fireball_flux: each fireball's blob at its sphere's flux

void main() {
    if (gl_GlobalInvocationID.x >= u_sphereCount) return;
    KilnInstance inst = kiln_instances[u_first + gl_GlobalInvocationID.x];
    vec3 centre = kilnSphereCentre(inst);
    float radius = kilnSphereRadius(inst);
    vec3 voxel = kilnCellSize(vec3(u_grid));
    ivec3 lo = max(ivec3(floor(kilnVolumeTexcoord(centre - radius) * vec3(u_grid))), ivec3(0));
    ivec3 hi = min(ivec3(floor(kilnVolumeTexcoord(centre + radius) * vec3(u_grid))), u_grid - 1);
#if KILN_SPLAT_LIT
    float flux = u_sphereFlux ? sphereFluxScale(radius) : 1.0;
    uvec3 emitted = toFixedRadiance(inst.emissive.rgb * u_fireballEmission * flux);
#else
    uvec3 emitted = toFixedRadiance(inst.emissive.rgb);
#endif
    for (int z = lo.z; z <= hi.z; ++z)
        for (int y = lo.y; y <= hi.y; ++y)
            for (int x = lo.x; x <= hi.x; ++x) {
                vec3 cubeLo = kilnGridToWorld(vec3(x, y, z) * (2.0 / vec3(u_grid)) - 1.0);
                vec3 cubeHi = cubeLo + voxel;
                float nearest = distance(clamp(centre, cubeLo, cubeHi), centre);
                float farthest = length(max(abs(cubeLo - centre), abs(cubeHi - centre)));
                if (nearest > radius || farthest < radius) continue;
#if KILN_SPLAT_LIT
                vec3 towards = 0.5 * (cubeLo + cubeHi) - centre;
                vec3 n = dot(towards, towards) > 1e-12 ? normalize(towards) : vec3(0.0, 1.0, 0.0);
                uvec3 lit = toFixedRadiance(lampReflected(inst.albedo.rgb, centre + n * radius, n));
                addSurfaceToVoxel(ivec3(x, y, z), lit, emitted, inst.albedo.rgb, n);
#else
                addToVoxel(ivec3(x, y, z), emitted);
#endif
            }
}
