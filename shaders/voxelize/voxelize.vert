#version 450 core
// Voxelization, stage 1: world-space triangles for the geometry shader.
#include "common/scene.glsl"

out vec3 vg_world;
out vec3 vg_normal;
flat out uint vg_instance;

void main() {
    KilnInstance inst = kilnInstance();
    vec4 world = inst.model * vec4(a_position, 1.0);
    vg_world = world.xyz;
    vg_normal = kilnWorldNormal(inst, a_normal);
    vg_instance = a_instance;
    gl_Position = world;
}
