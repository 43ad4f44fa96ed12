#version 450 core
// Depth of the placed meshes from a light, their alpha-masked materials cut out
// (shadow/cutout.frag): from the lamp (common/shadow.glsl), or with KILN_PUNCTUAL_LIGHT
// from punctual light u_light (the lights pass's atlas).
#include "common/scene.glsl"
#include "common/shadow.glsl"

layout(location = 3) in vec2 a_uv;

out vec2 v_uv;
flat out vec4 v_baseColor;
flat out vec4 v_layers;

#ifndef KILN_PUNCTUAL_LIGHT
#define KILN_PUNCTUAL_LIGHT 0
#endif
#if KILN_PUNCTUAL_LIGHT
uniform int u_light;
#endif

void main() {
    KilnInstance inst = kilnInstance();
    v_uv = a_uv;
    v_baseColor = inst.baseColor;
    v_layers = inst.layers;
    vec4 world = inst.model * vec4(a_position, 1.0);
#if KILN_PUNCTUAL_LIGHT
    gl_Position = u_punctual[u_light].shadowViewProj * world;
#else
    gl_Position = lightViewProj() * world;
#endif
}
