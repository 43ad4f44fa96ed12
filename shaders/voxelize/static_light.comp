#version 450 core
// voxelize, keep_static: the lamp light of the static surfaces' recorded fragments
// (static_surfaces.glsl), one invocation each, lit as voxelize.frag lights a fragment
// (surface.glsl: the same formula from the same irradiance, kept when the fragment was
// recorded, and this frame's shadow test of the same point, so the sums are those the
// raster would add) and added to the voxels of its depth span.
#include "common/frame.glsl"
#include "common/light.glsl"
#include "common/shadow.glsl"
#include "sums.glsl"
#include "surface.glsl"
#include "static_surfaces.glsl"
#include "common/punctual.glsl"

layout(local_size_x = 64) in;

void main() {
    if (gl_GlobalInvocationID.x >= min(u_recorded, u_capacity)) return;
    StaticFragment f = u_fragments[gl_GlobalInvocationID.x];
    vec3 irradiance = vec3(f.world.w, f.normal.w, f.albedo.w);
    vec3 reflected = lampReflected(f.albedo.rgb, irradiance, lampVisibility(f.world.xyz, f.normal.xyz));
#if KILN_PUNCTUAL
    reflected += f.albedo.rgb / 3.14159265 * punctualIrradiance(f.world.xyz, f.normal.xyz);
#endif
    uvec3 lit = toFixedRadiance(reflected);
    ivec3 step = ivec3(equal(ivec3(f.voxel.w & 3), ivec3(0, 1, 2)));
    for (int k = 0; k < f.voxel.w >> 2; ++k) {
        ivec3 v = f.voxel.xyz + k * step;
        addToSum(v, kSumR, lit.r);
        addToSum(v, kSumG, lit.g);
        addToSum(v, kSumB, lit.b);
    }
}
