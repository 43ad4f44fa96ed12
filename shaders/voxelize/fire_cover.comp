#version 450 core
// The particles' cover (voxelize's fire_cover on): how much of the light crossing each
// voxel the fire's particles stop, for common/fire.glsl to march the lamp's light
// through (the fireballs, few and large, it takes exactly). The
// particles are opaque spheres; seen as a medium, one of cross-section σ = π r² adds σ to
// the integral of the extinction coefficient μ over the volume (μ = number density × σ).
// Each particle's σ is shared among the voxels its bounding cube overlaps, in proportion
// to the overlap (separable: the product of the three axes' overlaps), and stored as
// μ·h, the optical depth across one voxel of side h: a voxel holding one sphere whose
// disc covers a fraction f of a face has μ·h = f. A particle (0.35 of its fireball's
// radius, a third of a 32³ voxel) lands in one to eight; what of its cube lies outside
// the box is in no voxel (no ray inside the box crosses it). Particles wholly inside a
// fireball are not in the scene's instances (host/scene/live_scene.cpp).
// One invocation per particle, instances [u_first, u_first + u_sphereCount), into the
// fixed-point channel kFireCover of the sums (fire_resolve.comp writes `fire`).
#include "sums.glsl"

layout(local_size_x = 64) in;

#include "common/frame.glsl"
#include "common/instances.glsl"

uniform uint u_first;
uniform uint u_sphereCount;
uniform ivec3 u_grid;  // voxels per axis

void main() {
    if (gl_GlobalInvocationID.x >= u_sphereCount) return;
    KilnInstance inst = kiln_instances[u_first + gl_GlobalInvocationID.x];
    vec3 centre = kilnSphereCentre(inst);
    float radius = kilnSphereRadius(inst);
    // In voxel units: the cube [lo, hi] around the sphere and the voxels it overlaps.
    vec3 voxel = kilnCellSize(vec3(u_grid));  // world
    vec3 lo = kilnVolumeTexcoord(centre - radius) * vec3(u_grid), hi = kilnVolumeTexcoord(centre + radius) * vec3(u_grid);
    ivec3 first = max(ivec3(floor(lo)), ivec3(0)), last = min(ivec3(floor(hi)), u_grid - 1);
    vec3 side = max(hi - lo, vec3(1e-6));
    // σ / h²: μ·h summed over a voxel's worth (h along the longest axis; the cells are
    // cubes wherever the fire is, the Cornell box's grid).
    float crossSection = 3.14159265 * radius * radius / (voxel.x * voxel.x);
    for (int z = first.z; z <= last.z; ++z)
        for (int y = first.y; y <= last.y; ++y)
            for (int x = first.x; x <= last.x; ++x) {
                vec3 cell = vec3(x, y, z);
                vec3 overlap = max(min(hi, cell + 1.0) - max(lo, cell), 0.0) / side;
                float share = crossSection * overlap.x * overlap.y * overlap.z;
                if (share > 0.0) addToSum(ivec3(x, y, z), kFireCover, uint(share * kCoverScale + 0.5));
            }
}
