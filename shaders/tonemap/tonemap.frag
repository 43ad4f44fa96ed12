#version 450 core
#include "common/tonemap.glsl"

in vec2 v_uv;
layout(location = 0) out vec4 o_color;

layout(binding = 0) uniform sampler2D u_hdr;
layout(binding = 1) uniform sampler2D u_bloom;
uniform float u_exposure;
uniform float u_gamma;
uniform int u_tonemap;

void main() {
    vec3 radiance = (texture(u_hdr, v_uv).rgb + texture(u_bloom, v_uv).rgb) * u_exposure;
    o_color = vec4(displayEncode(radiance, u_tonemap, u_gamma), 1.0);
}
