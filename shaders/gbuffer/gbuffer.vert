#version 450 core
#include "common/scene.glsl"

out vec3 v_world;
out vec3 v_normal;
// The material as flat varyings, read from the instance buffer once a vertex: read in
// the fragment shader, the buffer cost llvmpipe most of the pass, a gather per fragment.
flat out vec4 v_albedo;    // rgb, a = material (0 plain, 1 wood grain)
flat out vec4 v_emissive;  // rgb radiance, a = highlight

// gbuffer.cpp draws the scene twice, once per material: KILN_WOOD 1 the wood-grained
// instances, 0 the rest. An instance of the other material is moved outside the clip
// volume here (a few vertices) so it costs no fragment: llvmpipe runs both sides of a
// branch for every fragment, and the grain's lookup behind `if` cost every pixel of the
// G-buffer.
#ifndef KILN_WOOD
#define KILN_WOOD 0
#endif

void main() {
    KilnInstance inst = kilnInstance();
    vec4 world = inst.model * vec4(a_position, 1.0);
    v_world = world.xyz;
    v_normal = kilnWorldNormal(inst, a_normal);
    v_albedo = inst.albedo;
    v_emissive = inst.emissive;
    gl_Position = u_viewProj * world;
    if ((inst.albedo.a > 0.5) != bool(KILN_WOOD)) gl_Position = vec4(0.0, 0.0, 2.0, 1.0);  // beyond the far plane: clipped
}
