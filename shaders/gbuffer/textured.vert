#version 450 core
// The placed meshes (kSceneMeshes): their materials' textures, read per fragment
// (gbuffer/textured.frag).
#include "common/scene.glsl"

layout(location = 3) in vec2 a_uv;
layout(location = 4) in vec4 a_tangent;  // xyz, w = the bitangent's sign

out vec3 v_world;
out vec3 v_normal;
out vec2 v_uv;
out vec4 v_tangent;
flat out vec4 v_baseColor;
flat out vec4 v_emission;
flat out vec4 v_layers;  // base colour, emissive, normal map layer (-1 none), alpha cutoff

void main() {
    KilnInstance inst = kilnInstance();
    vec4 world = inst.model * vec4(a_position, 1.0);
    v_world = world.xyz;
    v_normal = kilnWorldNormal(inst, a_normal);
    v_tangent = vec4(mat3(inst.model) * a_tangent.xyz, a_tangent.w);
    v_uv = a_uv;
    v_baseColor = inst.baseColor;
    v_emission = inst.emission;
    v_layers = inst.layers;
    gl_Position = u_viewProj * world;
}
