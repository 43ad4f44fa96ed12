#version 450 core
// An alpha-masked material's fragment casts no shadow where its coverage (base colour
// factor × texture alpha) is below its cutoff, as the G-buffer cuts it (gbuffer/textured.frag).
layout(binding = 1) uniform sampler2DArray u_colorLayers;  // SceneView::materialTextures[0]

in vec2 v_uv;
flat in vec4 v_baseColor;
flat in vec4 v_layers;  // x base colour layer (-1 none), w alpha cutoff (0 opaque)

#ifndef KILN_HAS_COLOR_LAYERS
#define KILN_HAS_COLOR_LAYERS 1
#endif

void main() {
    float coverage = v_baseColor.a;
#if KILN_HAS_COLOR_LAYERS
    if (v_layers.x >= 0.0) coverage *= texture(u_colorLayers, vec3(v_uv, v_layers.x)).a;
#endif
    if (v_layers.w > 0.0 && coverage < v_layers.w) discard;
}
