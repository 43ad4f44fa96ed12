#version 450 core
// G-buffer of the placed meshes: albedo = base colour factor × texture (sRGB, decoded by
// the texture's format), a cut-out where an alpha-masked material's coverage is below its
// cutoff, the normal map in the tangent frame, emission = factor × emissive texture.
#include "common/frame.glsl"

layout(binding = 1) uniform sampler2DArray u_colorLayers;  // SceneView::materialTextures[0]
layout(binding = 2) uniform sampler2DArray u_dataLayers;   // [1]: normal maps

in vec3 v_world;
in vec3 v_normal;
in vec2 v_uv;
in vec4 v_tangent;
flat in vec4 v_baseColor;
flat in vec4 v_emission;
flat in vec4 v_layers;

layout(location = 0) out vec4 o_albedo;
layout(location = 1) out vec4 o_normal;
layout(location = 2) out vec4 o_emissive;

#ifndef KILN_HAS_COLOR_LAYERS
#define KILN_HAS_COLOR_LAYERS 1
#endif
#ifndef KILN_HAS_DATA_LAYERS
#define KILN_HAS_DATA_LAYERS 1
#endif

void main() {
    // Every lookup before the discard (kiln/pass.hpp, DERIVATIVES).
    vec4 base = v_baseColor;
    vec3 emission = v_emission.rgb;
#if KILN_HAS_COLOR_LAYERS
    if (v_layers.x >= 0.0) base *= texture(u_colorLayers, vec3(v_uv, v_layers.x));
    if (v_layers.y >= 0.0) emission *= texture(u_colorLayers, vec3(v_uv, v_layers.y)).rgb;
#endif
    vec3 n = normalize(v_normal);
    if (!gl_FrontFacing) n = -n;
#if KILN_HAS_DATA_LAYERS
    if (v_layers.z >= 0.0) {
        vec3 m = texture(u_dataLayers, vec3(v_uv, v_layers.z)).xyz * 2.0 - 1.0;
        vec3 t = v_tangent.xyz - n * dot(n, v_tangent.xyz);
        if (dot(t, t) > 1e-12) {
            t = normalize(t);
            vec3 b = cross(n, t) * (v_tangent.w < 0.0 ? -1.0 : 1.0);
            n = normalize(m.x * t + m.y * b + m.z * n);
        }
    }
#endif
    if (v_layers.w > 0.0 && base.a < v_layers.w) discard;
    o_albedo = vec4(base.rgb, 1.0);
    o_normal = vec4(n, 1.0);
    o_emissive = vec4(emission, 1.0);
}
