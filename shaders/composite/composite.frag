#version 450 core
// Direct diffuse light from the lamp (≈ a point light at its centre, I = k_d·I_l·cos θ)
// with the seed's "directional" attenuation by the angle between the light direction
// and +y (the hemisphere lamp shades the wall tops), plus emission, indirect, bloom.
#include "common/frame.glsl"
#include "common/light.glsl"

in vec2 v_uv;
layout(location = 0) out vec4 o_color;
layout(location = 1) out vec4 o_hdr;

layout(binding = 0) uniform sampler2D u_albedo;
layout(binding = 1) uniform sampler2D u_normal;
layout(binding = 2) uniform sampler2D u_depth;
layout(binding = 3) uniform sampler2D u_emissive;
layout(binding = 4) uniform sampler2D u_shadowMap;
layout(binding = 5) uniform sampler2D u_indirect;
layout(binding = 6) uniform sampler2D u_bloom;

uniform float u_exposure;
uniform float u_ambient;
uniform float u_gamma;
uniform int u_tonemap;
uniform int u_pcf;
uniform float u_shadowBias;
uniform float u_indirectStrength;

// Fraction of the lamp that sees p: a k×k percentage-closer filter over the shadow
// map (k = u_pcf; 1 is a hard shadow). No map bound: everything is lit.
float lightVisibility(vec3 p) {
#if KILN_HAS_SHADOW_MAP
    return shadowVisibility(u_shadowMap, p, u_pcf, u_shadowBias);
#else
    return 1.0;
#endif
}

vec3 worldPosition(vec2 uv, float depth) {
    vec4 p = u_invViewProj * vec4(uv * 2.0 - 1.0, depth * 2.0 - 1.0, 1.0);
    return p.xyz / p.w;
}

vec3 tonemap(vec3 x) {
    if (u_tonemap == 0) {  // ACES filmic fit (Narkowicz 2015)
        return clamp((x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14), 0.0, 1.0);
    }
    if (u_tonemap == 1) return x / (1.0 + x);
    return clamp(x, 0.0, 1.0);
}

void main() {
    vec4 n4 = texture(u_normal, v_uv);
    vec3 emissive = texture(u_emissive, v_uv).rgb;
    vec3 radiance = vec3(0.0);
    if (n4.w > 0.5) {
        vec3 albedo = texture(u_albedo, v_uv).rgb;
        vec3 p = worldPosition(v_uv, texture(u_depth, v_uv).r);
        vec3 n = normalize(n4.xyz);
        float cosTheta = max(dot(n, normalize(u_lightPos.xyz - p)), 0.0);
        float visible = cosTheta > 0.0 ? lightVisibility(p + n * 0.004) : 0.0;
        vec3 direct = albedo / 3.14159265 * lampLight(p, n) * visible;
        vec3 indirect = albedo * u_indirectStrength * texture(u_indirect, v_uv).rgb;
#if KILN_HAS_INDIRECT == 0
        indirect = albedo * u_ambient;
#endif
        radiance = direct + indirect;
    }
    radiance += emissive + texture(u_bloom, v_uv).rgb;
    radiance *= u_exposure;
    o_hdr = vec4(radiance, 1.0);
    o_color = vec4(pow(tonemap(radiance), vec3(1.0 / u_gamma)), 1.0);
}
