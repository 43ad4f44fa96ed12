#version 450 core
// G-buffer: albedo (sRGB-free linear rgb), world-space normal, emitted radiance.
#include "common/frame.glsl"
#include "gbuffer/highlight.glsl"

layout(binding = 1) uniform sampler2D u_wood;  // the floor's grain over x, z in [-1,1] (gbuffer/wood.comp)

in vec3 v_world;
in vec3 v_normal;
flat in vec4 v_albedo;    // rgb, a = material (0 plain, 1 wood grain: drawn with KILN_WOOD 1, gbuffer.vert)
flat in vec4 v_emissive;  // rgb radiance, a = highlight

layout(location = 0) out vec4 o_albedo;
layout(location = 1) out vec4 o_normal;    // xyz world-space unit normal, w = 1 where geometry
layout(location = 2) out vec4 o_emissive;  // rgb radiance, a = 1 (2: a particle, gbuffer.cpp)

void main() {
#if KILN_WOOD
    vec3 albedo = texture(u_wood, v_world.xz * 0.5 + 0.5).rgb;
#else
    vec3 albedo = v_albedo.rgb;
#endif
    vec3 n = normalize(v_normal);
    if (!gl_FrontFacing) n = -n;
    vec3 emissive = emissionOf(v_emissive);
    o_albedo = vec4(albedo, 1.0);
    o_normal = vec4(n, 1.0);
#if KILN_PARTICLE
    o_emissive = vec4(emissive, 2.0);  // a particle's mesh: only this is written (gbuffer.cpp)
#else
    o_emissive = vec4(emissive, 1.0);
#endif
}
