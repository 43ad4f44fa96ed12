#version 450 core
// Voxelization, stage 3: light the fragment (direct light with a hard shadow, plus
// emission) and add it to every voxel its depth spans inside this pixel column.
// Combination rule: exact average via atomic adds of fixed-point sums and a count
// (passes/voxelize/voxelize.cpp explains why).
#include "common/frame.glsl"
#include "common/instances.glsl"
#include "common/light.glsl"
#include "common/luminance.glsl"
#include "common/shadow.glsl"
#include "common/wood.glsl"
#include "sums.glsl"
#include "surface.glsl"
#include "common/punctual.glsl"
#if KILN_RECORD_STATIC
#include "static_surfaces.glsl"
#endif

in vec3 v_world;
in vec3 v_normal;
flat in uint v_instance;
flat in int v_axis;
flat in vec4 v_aabb;
flat in vec2 v_depthRange;

// The voxel at depth index k of pixel column ij, projected along `axis`: the inverse of
// the geometry shader's swizzle.
ivec3 voxelAt(int k, ivec2 ij, int axis) { return axis == 0 ? ivec3(k, ij.x, ij.y) : axis == 1 ? ivec3(ij.y, k, ij.x) : ivec3(ij, k); }

uniform float u_emissionScale;  // 1, or lamp_emission while drawing the lamp
uniform int u_axisViewportStep;  // the axes' viewports lie this many pixels apart in x (voxelize.geom)
uniform bool u_sphereFlux;      // the fireballs: scale each to its sphere's flux (below)
uniform bool u_twoSided;        // a double-sided material (voxelize.cpp draws those apart)

// A double-sided surface as the side its light falls on: n, or −n where the lights reach
// that side more. A voxel keeps one radiance and one normal, so the lit side is the one
// it shows; with the normal as authored, a room's walls wound outward were lit from
// behind (black) and their voxels faced away from the room.
vec3 sideLit(vec3 p, vec3 n) {
    vec3 front = lampIrradiance(p, n), back = lampIrradiance(p, -n);
#if KILN_PUNCTUAL
    front += punctualIrradiance(p, n), back += punctualIrradiance(p, -n);
#endif
    return kilnLuminance(back) > kilnLuminance(front) ? -n : n;
}

void main() {
    // Depth along the projection axis at this pixel, and how much it varies across it:
    // taken before the discard below, while the whole 2x2 quad still runs. After it the
    // derivative is undefined - llvmpipe only masks a discarded lane and still gave the
    // right span, NVIDIA's driver does not, and its tumblers' shells lost voxels where
    // their surfaces turn steep (the indirect light under them far brighter than llvmpipe's).
    vec3 q = kilnWorldToGrid(v_world);
    float depth = v_axis == 0 ? q.x : v_axis == 1 ? q.y : q.z;
    float span = 0.5 * (abs(dFdx(depth)) + abs(dFdy(depth)));

    vec2 px = gl_FragCoord.xy - vec2(float(v_axis * u_axisViewportStep), 0.0);
    if (px.x < v_aabb.x || px.y < v_aabb.y || px.x > v_aabb.z || px.y > v_aabb.w) discard;

    KilnInstance inst = kiln_instances[v_instance];
    vec3 albedo = inst.albedo.rgb;
    if (inst.albedo.a > 0.5) albedo = woodGrain(v_world);
    vec3 n = normalize(v_normal);
    if (u_twoSided) n = sideLit(v_world, n);
    float scale = u_emissionScale;
    if (u_sphereFlux) scale *= sphereFluxScale(kilnSphereRadius(inst));
    uvec3 emitted = toFixedRadiance(inst.emissive.rgb * scale);

    float zLo = clamp(depth - span, v_depthRange.x, v_depthRange.y);
    float zHi = clamp(depth + span, v_depthRange.x, v_depthRange.y);
    // The viewport's columns and the layers along the axis (voxelize.geom's swizzle).
    ivec3 cells = v_axis == 0 ? u_grid.yzx : v_axis == 1 ? u_grid.zxy : u_grid;
    int k0 = clamp(int(floor((zLo * 0.5 + 0.5) * float(cells.z))), 0, cells.z - 1);
    int k1 = clamp(int(floor((zHi * 0.5 + 0.5) * float(cells.z))), 0, cells.z - 1);
    ivec2 ij = clamp(ivec2(px), ivec2(0), cells.xy - 1);
    int kLast = min(k1, k0 + 2);
#if KILN_RECORD_STATIC
    // A static surface: everything but its lamp light now, the fragment kept for
    // static_light.comp to light each frame.
    uvec3 lit = uvec3(0u);
    uint slot = atomicAdd(u_recorded, 1u);
    if (slot < u_capacity) {
        vec3 irradiance = lampIrradiance(v_world, n);
        u_fragments[slot] = StaticFragment(vec4(v_world, irradiance.r), vec4(n, irradiance.g), vec4(albedo, irradiance.b),
                                           ivec4(voxelAt(k0, ij, v_axis), v_axis | (kLast - k0 + 1) << 2));
    }
#else
    vec3 reflected = lampReflected(albedo, v_world, n);
#if KILN_PUNCTUAL
    reflected += albedo / 3.14159265 * punctualIrradiance(v_world, n);
#endif
    uvec3 lit = toFixedRadiance(reflected);
#endif
    for (int k = k0; k <= kLast; ++k) addSurfaceToVoxel(voxelAt(k, ij, v_axis), lit, emitted, albedo, n);
}
