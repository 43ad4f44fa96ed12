#version 450 core
// fire_cover: `lamp_transmittance`, the fraction of the lamp each node of a grid half the
// voxels' resolution sees past the fire (common/fire.glsl: the fireballs exactly, the
// particles through `fire`), facing the lamp. resolve.comp takes each voxel's lamp light
// through it and cone_trace each traced pixel's: one lookup where a march per voxel cost
// voxelize 7 -> 13 ms at 720² on llvmpipe. The lamp is large, so the fraction changes
// slowly away from the fire.
layout(local_size_x = 4, local_size_y = 4, local_size_z = 4) in;

#include "common/frame.glsl"
#include "common/instances.glsl"
#include "common/shadow.glsl"
#include "common/fire.glsl"

layout(r16f, binding = 0) uniform writeonly image3D u_transmittance;

void main() {
    ivec3 v = ivec3(gl_GlobalInvocationID);
    ivec3 size = imageSize(u_transmittance);
    if (any(greaterThanEqual(v, size))) return;
    vec3 node = (vec3(v) + 0.5) / vec3(size) * 2.0 - 1.0;
    vec3 towards = lightEye() - node;
    vec3 n = dot(towards, towards) > 1e-8 ? normalize(towards) : vec3(0.0, 1.0, 0.0);
    imageStore(u_transmittance, v, vec4(fireTransmittance(node, n)));
}
