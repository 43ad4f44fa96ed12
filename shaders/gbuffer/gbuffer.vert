#version 450 core
#include "common/scene.glsl"

out vec3 v_world;
out vec3 v_normal;
flat out uint v_instance;

void main() {
    KilnInstance inst = kilnInstance();
    vec4 world = inst.model * vec4(a_position, 1.0);
    v_world = world.xyz;
    v_normal = kilnWorldNormal(inst, a_normal);
    v_instance = a_instance;
    gl_Position = u_viewProj * world;
}
