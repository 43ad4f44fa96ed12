#version 450 core
// Direct diffuse light from the lamp (the emitter of common/light.glsl, shadowed by a
// PCF lookup from its centre), plus albedo × indirect irradiance, emission and bloom.
// `hdr` is the radiance estimate before bloom and exposure, the image the error
// metrics compare with the reference.
#include "common/frame.glsl"
#include "common/light.glsl"
#include "common/tonemap.glsl"

in vec2 v_uv;
layout(location = 0) out vec4 o_color;
layout(location = 1) out vec4 o_hdr;

layout(binding = 0) uniform sampler2D u_albedo;
layout(binding = 1) uniform sampler2D u_normal;
layout(binding = 2) uniform sampler2D u_depth;
layout(binding = 3) uniform sampler2D u_emissive;
layout(binding = 4) uniform sampler2DShadow u_shadowMap;  // a comparison sampler is bound with it
layout(binding = 5) uniform sampler2D u_indirect;
layout(binding = 6) uniform sampler2D u_bloom;

uniform float u_exposure;
uniform float u_ambient;
uniform float u_gamma;
uniform int u_tonemap;   // kTonemapAces, kTonemapReinhard, kTonemapClamp
uniform float u_shadowBias;
uniform float u_indirectStrength;
uniform float u_lampNearField;  // lamp_model traced: metres from the dome evaluated per pixel

// Fraction of the lamp that sees p: a k×k percentage-closer filter over the shadow
// map (k = KILN_PCF; 1 is one bilinear test). No map bound: everything is lit.
float lightVisibility(vec3 p) {
#if KILN_HAS_SHADOW_MAP
    return shadowFiltered(u_shadowMap, p, u_shadowBias);
#else
    return 1.0;
#endif
}

vec3 worldPosition(vec2 uv, float depth) {
    vec4 p = u_invViewProj * vec4(uv * 2.0 - 1.0, depth * 2.0 - 1.0, 1.0);
    return p.xyz / p.w;
}

void main() {
    // The G-buffer inputs are the output's size: texel fetches. The indirect light and
    // the bloom may be smaller (cone_trace.output_divisor, bloom at half size): filtered.
    ivec2 px = ivec2(gl_FragCoord.xy);
    vec4 n4 = texelFetch(u_normal, px, 0);
    // The optional ones may be the 1×1 fallback: clamped.
    vec3 emissive = texelFetch(u_emissive, min(px, textureSize(u_emissive, 0) - 1), 0).rgb;
    vec3 radiance = vec3(0.0);
    if (n4.w > 0.5) {
        vec3 albedo = texelFetch(u_albedo, px, 0).rgb;
        vec3 p = worldPosition(v_uv, texelFetch(u_depth, px, 0).r);
        vec3 n = normalize(n4.xyz);
#if KILN_LAMP_TRACED
        // cone_trace's `lamp`: the projected solid angle where it traced, upsampled. Within
        // u_lampNearField of the dome it changes faster than those samples: evaluated
        // here, by the variant composite.cpp draws over the near field's screen
        // rectangle only (on llvmpipe the contour's mere presence in the shader cost
        // every pixel of the frame, used or not).
        float solidAngle = texture(u_indirect, v_uv).a;
#if KILN_LAMP_NEAR_FIELD
        if (distance(p, u_lightPos.xyz) < u_lightPos.w + u_lampNearField) solidAngle = lampProjectedSolidAngle(p, n);
#endif
        vec3 irradiance = u_lightColor.rgb * solidAngle;
#else
        vec3 irradiance = lampLight(p, n);
#endif
        float visible = max(irradiance.r, max(irradiance.g, irradiance.b)) > 0.0 ? lightVisibility(p + n * 0.004) : 0.0;
        vec3 direct = albedo / 3.14159265 * irradiance * visible;
        vec3 indirect = albedo * u_indirectStrength * texture(u_indirect, v_uv).rgb;
#if KILN_HAS_INDIRECT == 0
        indirect = albedo * u_ambient;
#endif
        radiance = direct + indirect;
    }
    radiance += emissive;
    o_hdr = vec4(radiance, 1.0);
    vec3 shown = (radiance + texture(u_bloom, v_uv).rgb) * u_exposure;
    o_color = vec4(displayEncode(shown, u_tonemap, u_gamma), 1.0);
}
