#version 450 core
#include "common/scene.glsl"

out vec3 v_world;
out vec3 v_normal;
// The material as flat varyings, read from the instance buffer once a vertex: read in
// the fragment shader, the buffer cost llvmpipe 14 of the pass's 20 ms at 720² (an
// empty box), a gather per fragment.
flat out vec4 v_albedo;    // rgb, a = material (0 plain, 1 wood grain)
flat out vec4 v_emissive;  // rgb radiance, a = highlight

void main() {
    KilnInstance inst = kilnInstance();
    vec4 world = inst.model * vec4(a_position, 1.0);
    v_world = world.xyz;
    v_normal = kilnWorldNormal(inst, a_normal);
    v_albedo = inst.albedo;
    v_emissive = inst.emissive;
    gl_Position = u_viewProj * world;
}
