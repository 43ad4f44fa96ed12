#version 450 core
// fire_cover: `lamp_transmittance`, the fraction of the lamp each node of a grid of
// voxelize's transmittance_resolution³ sees past the fire (common/fire.glsl: the fireballs exactly, the
// particles through `fire`), facing the lamp. resolve.comp takes each voxel's lamp light
// through it and cone_trace each traced pixel's: one lookup where a march per voxel
// would cost far more. The lamp is large, so the fraction changes slowly away from the
// fire.
layout(local_size_x = 4, local_size_y = 4, local_size_z = 4) in;

#include "common/frame.glsl"
#include "common/instances.glsl"
#include "common/shadow.glsl"
#include "common/fire.glsl"

layout(r16f, binding = 0) uniform writeonly image3D u_transmittance;
uniform int u_firstFireball, u_fireballCount;

// The fireballs that may hide part of the lamp from some node of this workgroup's 4³
// block: those within the capsule from the block's centre to the lamp's, as thick as the
// larger of the block's and the lamp's bounding spheres (the hull of every segment from
// the block to the lamp lies inside it): every node testing every fireball is dear on
// llvmpipe with many of them.
shared vec4 s_fireballs[kFireMaxFireballs];
shared uint s_count;
int fireballCount() { return int(s_count); }
vec4 fireballSphere(int i) { return s_fireballs[i]; }

void main() {
    ivec3 size = imageSize(u_transmittance);
    if (gl_LocalInvocationIndex == 0u) s_count = 0u;
    barrier();
    vec3 blockLo = kilnGridToWorld(vec3(gl_WorkGroupID * gl_WorkGroupSize) / vec3(size) * 2.0 - 1.0);
    vec3 blockHi = kilnGridToWorld(vec3((gl_WorkGroupID + 1u) * gl_WorkGroupSize) / vec3(size) * 2.0 - 1.0);
    vec3 blockCentre = 0.5 * (blockLo + blockHi);
    float thickness = max(0.5 * length(blockHi - blockLo), u_lightPos.w);
    vec3 axis = u_lightPos.xyz - blockCentre;
    for (int i = int(gl_LocalInvocationIndex); i < u_fireballCount; i += 64) {
        KilnInstance f = kiln_instances[u_firstFireball + i];
        vec3 c = kilnSphereCentre(f);
        float s = clamp(dot(c - blockCentre, axis) / max(dot(axis, axis), 1e-12), 0.0, 1.0);
        if (distance(c, blockCentre + s * axis) < thickness + kilnSphereRadius(f)) {
            uint slot = atomicAdd(s_count, 1u);
            if (slot < uint(kFireMaxFireballs)) s_fireballs[slot] = vec4(c, kilnSphereRadius(f));
        }
    }
    barrier();
    ivec3 v = ivec3(gl_GlobalInvocationID);
    if (any(greaterThanEqual(v, size))) return;
    vec3 node = kilnGridToWorld((vec3(v) + 0.5) / vec3(size) * 2.0 - 1.0);
    vec3 towards = lightEye() - node;
    vec3 n = dot(towards, towards) > 1e-8 ? normalize(towards) : vec3(0.0, 1.0, 0.0);
    imageStore(u_transmittance, v, vec4(fireTransmittance(node, n)));
}
