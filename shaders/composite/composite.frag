#version 450 core
// Direct diffuse light from the lamp (the emitter of common/light.glsl, shadowed by a
// PCF lookup from its centre), plus albedo × indirect irradiance, emission and bloom.
// `hdr` is the radiance estimate before bloom and exposure, the image the error
// metrics compare with the reference.
// KILN_DIRECT: 0 computes the lamp's light here; 1 does and also writes it to `direct`
// (the pass's cache of what depends only on the G-buffer, the shadow map and the lamp;
// alpha the frame that computed it); 2 reads it from there. All three shade from the
// light as `direct` keeps it (asKept), by one function: a pixel comes out the same
// whichever drew it, and with keep_direct off (composite.cpp).
#include "common/frame.glsl"
#include "common/light.glsl"
#include "common/shadow.glsl"
#include "common/lamp_field.glsl"
#include "common/tonemap.glsl"
#include "common/punctual.glsl"

#ifndef KILN_DIRECT
#define KILN_DIRECT 0
#endif
#ifndef KILN_HDR
#define KILN_HDR 1
#endif
// KILN_HDR 0: nothing reads `hdr` (PassContext::isRead), which is then not a target.
layout(location = 0) out vec4 o_color;
#if KILN_HDR
layout(location = 1) out vec4 o_hdr;
#endif
#if KILN_DIRECT == 1 && KILN_HDR
layout(location = 2) out vec4 o_direct;
#elif KILN_DIRECT == 1
layout(location = 1) out vec4 o_direct;
#endif
#if KILN_DIRECT == 2
layout(binding = 9) uniform sampler2D u_direct;
#endif

layout(binding = 0) uniform sampler2D u_albedo;
layout(binding = 1) uniform sampler2D u_normal;
layout(binding = 2) uniform sampler2D u_depth;
layout(binding = 3) uniform sampler2D u_emissive;
layout(binding = 4) uniform sampler2DShadow u_shadowMap;  // a comparison sampler is bound with it
layout(binding = 5) uniform sampler2D u_indirect;
layout(binding = 6) uniform sampler2D u_bloom;
#if KILN_PCSS
layout(binding = 7) uniform sampler2D u_shadowDepth;  // the same map, raw depths (texelFetch: no sampler state)
#endif

uniform float u_exposure;
uniform float u_ambient;
uniform float u_gamma;
uniform int u_tonemap;   // kTonemapAces, kTonemapReinhard, kTonemapClamp
uniform float u_shadowBias;
uniform float u_indirectStrength;
#if KILN_LAMP_FIELD
layout(binding = 8) uniform sampler2D u_lampField;  // F on the lamp's axisymmetric grid (common/lamp_field.comp)
#endif
uniform float u_lampNearField;  // lamp_model traced or field: metres from the dome evaluated per pixel

#if KILN_PCSS && KILN_HAS_SHADOW_MAP
// Metres along the lamp's view axis of a shadow-map depth in [0, 1].
float lightLinearDepth(float depth) {
    float z = depth * 2.0 - 1.0;
    return 2.0 * kLightNear * kLightFar / (kLightFar + kLightNear - z * (kLightFar - kLightNear));
}

// Soft shadows sized by the lamp (percentage-closer soft shadows, Fernando 2005). The
// lamp is taken as a disc of radius R = u_lightPos.w at the map's centre of projection.
// A blocker at depth d_b hides part of it from p (at depth d_r) when it lies within
// R (d_r − d_b) / (2 tan 70° d_b d_r) of p's point in the map (the map spans 140°): its
// penumbra's half-width there. 1) The blockers: a 5×5 grid of raw depths over the widest
// such region (blockers no nearer the lamp than kPcssNearest); none: lit. 2) A 4×4 grid
// of comparison lookups (each a bilinear blend of four tests) over the penumbra of their
// mean depth, never narrower than one texel apart.
const float kPcssNearest = 0.4;
float shadowSoft(sampler2DShadow shadowMap, sampler2D depths, vec3 p, float bias) {
    vec4 ls = lightSpace(p);
    if (ls.w == 0.0) return 1.0;
    const float perMetre = 0.5 / tan(radians(70.0));
    float receiver = lightLinearDepth(ls.z), radius = u_lightPos.w;
    vec2 size = vec2(textureSize(depths, 0));
    float search = radius * perMetre * max(receiver - kPcssNearest, 0.0) / (kPcssNearest * receiver);
    float sum = 0.0, blockers = 0.0;
    for (int y = 0; y < 5; ++y)
        for (int x = 0; x < 5; ++x) {
            vec2 uv = ls.xy + (vec2(x, y) - 2.0) * 0.5 * search;
            float d = texelFetch(depths, ivec2(clamp(uv, vec2(0.0), vec2(1.0)) * (size - 1.0)), 0).r;
            if (d < ls.z - bias) sum += lightLinearDepth(d), blockers += 1.0;
        }
    if (blockers == 0.0) return 1.0;
    float blocker = sum / blockers;
    float penumbra = radius * perMetre * max(receiver - blocker, 0.0) / (blocker * receiver);
    vec2 spacing = max(vec2(penumbra / 1.5), 1.0 / size);
    float lit = 0.0;
    for (int y = 0; y < 4; ++y)
        for (int x = 0; x < 4; ++x) lit += texture(shadowMap, vec3(ls.xy + (vec2(x, y) - 1.5) * spacing, ls.z - bias));
    return lit / 16.0;
}
#endif

#if KILN_FIREBALLS_ANALYTIC
#include "common/instances.glsl"
uniform int u_firstFireball, u_fireballCount;
// The fireballs' irradiance at p: each a sphere of uniform radiance L, E = π L (r/d)² cos θ
// (exact while the whole sphere is above p's horizon; they are small), unshadowed.
vec3 fireballIrradiance(vec3 p, vec3 n) {
    vec3 e = vec3(0.0);
    for (int i = 0; i < u_fireballCount; ++i) {
        KilnInstance f = kiln_instances[u_firstFireball + i];
        vec3 toCentre = kilnSphereCentre(f) - p;
        float d2 = dot(toCentre, toCentre), r = kilnSphereRadius(f);
        float cosTheta = dot(n, toCentre) * inversesqrt(max(d2, 1e-8));
        e += f.emissive.rgb * (3.14159265 * r * r / max(d2, r * r)) * max(cosTheta, 0.0);
    }
    return e;
}
#endif

// Fraction of the lamp that sees p: a k×k percentage-closer filter over the shadow
// map (k = KILN_PCF; 1 is one bilinear test), or one sized by the lamp (KILN_PCSS). No
// map bound: everything is lit.
float lightVisibility(vec3 p) {
#if KILN_HAS_SHADOW_MAP && KILN_PCSS
    return shadowSoft(u_shadowMap, u_shadowDepth, p, u_shadowBias);
#elif KILN_HAS_SHADOW_MAP
    return shadowFiltered(u_shadowMap, p, u_shadowBias);
#else
    return 1.0;
#endif
}

vec3 worldPosition(vec2 uv, float depth) {
    vec4 p = u_invViewProj * vec4(uv * 2.0 - 1.0, depth * 2.0 - 1.0, 1.0);
    return p.xyz / p.w;
}

// The lamp's light at the pixel before the fire dims it: albedo / π × irradiance ×
// the shadow test; 0 where no geometry is.
vec3 lampDirect(ivec2 px, vec2 uv, vec4 n4, vec3 albedo) {
    if (n4.w <= 0.5) return vec3(0.0);
    vec3 p = worldPosition(uv, texelFetch(u_depth, px, 0).r);
    vec3 n = normalize(n4.xyz);
#if KILN_LAMP_TRACED || KILN_LAMP_FIELD
    // traced: cone_trace's `lamp`, the projected solid angle where it traced,
    // upsampled. field: from the lamp's vector irradiance F on a grid, n·F (exact up
    // to the grid where the whole emitter is above the surface's horizon) or, where
    // the horizon cuts it, the clipped form of the ball F describes (common/lamp_field.glsl).
    // Within u_lampNearField of the dome both change faster than their samples:
    // evaluated here, by the variant composite.cpp draws over the near field's
    // screen rectangle only (on llvmpipe the contour's mere presence in the shader
    // cost every pixel of the frame, used or not).
#if KILN_LAMP_FIELD
    float solidAngle = lampFieldSolidAngle(lampFieldAt(u_lampField, p), p, n);
#else
    float solidAngle = texture(u_indirect, uv).a;
#endif
#if KILN_LAMP_NEAR_FIELD
    if (distance(p, u_lightPos.xyz) < u_lightPos.w + u_lampNearField) solidAngle = lampProjectedSolidAngle(p, n);
#endif
    vec3 irradiance = u_lightColor.rgb * solidAngle;
#else
    vec3 irradiance = lampLight(p, n);
#endif
    float visible = max(irradiance.r, max(irradiance.g, irradiance.b)) > 0.0 ? lightVisibility(p + n * 0.004) : 0.0;
    return albedo / 3.14159265 * irradiance * visible;
}

// The pixel's radiance from its lamp light (lampDirect): dimmed by the fire, plus the
// fireballs' light, albedo × the indirect light, and its emission. Where no geometry is
// the albedo and the lamp light are 0 (gbuffer's background): emission only. Where a
// particle hides the surface (emission's alpha 2; the G-buffer's other outputs are the
// surface's, so the lamp light kept for it stays good when the particle moves on) the
// particle's emission only: it has no albedo.
vec3 shade(ivec2 px, vec2 uv, vec3 lampLit, vec3 albedo) {
    vec4 indirectLight = texture(u_indirect, uv);
    vec3 direct = lampLit;
#if KILN_LAMP_THROUGH_FIRE
    direct *= indirectLight.a;  // through the fire (common/fire.glsl), upsampled
#endif
#if KILN_PUNCTUAL
    if (texelFetch(u_normal, px, 0).w > 0.5) {
        vec3 p = worldPosition(uv, texelFetch(u_depth, px, 0).r);
        direct += albedo / 3.14159265 * punctualIrradiance(p, normalize(texelFetch(u_normal, px, 0).xyz));
    }
#endif
#if KILN_FIREBALLS_ANALYTIC
    if (texelFetch(u_normal, px, 0).w > 0.5) {
        vec3 p = worldPosition(uv, texelFetch(u_depth, px, 0).r);
        direct += albedo / 3.14159265 * fireballIrradiance(p, normalize(texelFetch(u_normal, px, 0).xyz));
    }
#endif
#if KILN_HAS_INDIRECT
    vec3 indirect = albedo * u_indirectStrength * indirectLight.rgb;
#else
    vec3 indirect = albedo * u_ambient;
#endif
    // The optional emission may be the 1×1 fallback: clamped.
    vec4 emission = texelFetch(u_emissive, min(px, textureSize(u_emissive, 0) - 1), 0);
    return emission.a > 1.5 ? emission.rgb : direct + indirect + emission.rgb;
}

// The lamp light as `direct` keeps it (RGBA16F: an RGBA32F fetch is dearer on llvmpipe
// than a half one): rounded to halves, below the smallest normal half taken
// as 0 (a render target may flush what packHalf2x16 keeps). Every variant shades from
// it so, whether it computed the light or read it back: the picture is the same
// with keep_direct on or off (the hdr output is halves too).
// Rounded to 11 significant bits, to nearest even, by integer steps: what
// packHalf2x16 and back give (the picture identical both ways), for a light ≥ 0 and
// far below the largest half.
vec3 asKept(vec3 light) {
    uvec3 bits = floatBitsToUint(light);
    bits = (bits + 0xFFFu + ((bits >> 13) & 1u)) & ~0x1FFFu;
    return mix(uintBitsToFloat(bits), vec3(0.0), lessThan(light, vec3(6.103515625e-5)));
}

void main() {
    // The G-buffer inputs are the output's size: texel fetches. The indirect light and
    // the bloom may be smaller (cone_trace.output_divisor, bloom at half size): filtered.
    // Coordinates from the fragment, not a varying: every way this shader is drawn
    // (the screen's triangle, composite.cpp's tiles) reads the same.
    ivec2 px = ivec2(gl_FragCoord.xy);
    vec2 uv = gl_FragCoord.xy * u_outputSize.zw;
    vec3 albedo = texelFetch(u_albedo, px, 0).rgb;
#if KILN_DIRECT == 2
    vec3 lampLit = texelFetch(u_direct, px, 0).rgb;
#else
    vec3 lampLit = asKept(lampDirect(px, uv, texelFetch(u_normal, px, 0), albedo));
#endif
#if KILN_DIRECT == 1
    o_direct = vec4(lampLit, mod(u_time.z, 1024.0) + 1.0);  // a: the frame that computed it (mod 1024) + 1
#endif
    vec3 radiance = shade(px, uv, lampLit, albedo);
#if KILN_HDR
    o_hdr = vec4(radiance, 1.0);
#endif
    vec3 shown = (radiance + texture(u_bloom, uv).rgb) * u_exposure;
    o_color = vec4(displayEncode(shown, u_tonemap, u_gamma), 1.0);
}
