// The lamp's shadow projection, shared by the shadow pass and everything that reads
// its map: a perspective view looking straight down from one point of the lamp, so one
// 2D map covers the box below it.
// That point is the centroid of the emitter's surface (the cap of the lamp's ball below
// the ceiling: its area grows evenly with depth, so the centroid sits half way down
// it), not the ball's centre above the ceiling: a hard shadow cast from the centre is
// shorter than the lamp's penumbra centred on the cap; cast from the cap, the floor's
// direct light is closer to the path tracer's in kiln-bench-quality. Casters within
// kLightNear below that point or above it (a marble by the dome) cast nothing.
// 140° field of view: the floor and every caster are inside; the walls' upper parts
// (above about half a metre below the eye, receivers only, already shaded by the
// lamp's directional falloff) fall outside and read as lit.
// Apart from common/light.glsl (the lamp itself) so that the reference, which traces
// its shadows, does not read it: kiln-bench-quality keys its cached reference on the
// files the reference's shader reads.
#include "frame.glsl"
#include "light.glsl"

const float kLightNear = 0.05;
const float kLightFar = 3.5;

// The eye: the centroid of the lamp's cap below the ceiling.
vec3 lightEye() { return vec3(u_lightPos.x, 0.5 * (u_lightPos.y - u_lightPos.w + kCeilingY), u_lightPos.z); }

mat4 lightViewProj() {
    vec3 eye = lightEye();
    // lookAt(eye, eye − y, up = −z)
    mat4 view = mat4(1.0, 0.0, 0.0, 0.0,
                     0.0, 0.0, 1.0, 0.0,
                     0.0, -1.0, 0.0, 0.0,
                     -eye.x, eye.z, -eye.y, 1.0);
    float f = 1.0 / tan(radians(140.0) * 0.5);
    mat4 proj = mat4(f, 0.0, 0.0, 0.0,
                     0.0, f, 0.0, 0.0,
                     0.0, 0.0, (kLightFar + kLightNear) / (kLightNear - kLightFar), -1.0,
                     0.0, 0.0, 2.0 * kLightFar * kLightNear / (kLightNear - kLightFar), 0.0);
    return proj * view;
}

// Shadow-map coordinates of a world point: xy in [0,1], z = depth in [0,1]; w = 0
// when the point is outside the light's frustum.
vec4 lightSpace(vec3 world) {
    vec4 c = lightViewProj() * vec4(world, 1.0);
    vec3 ndc = c.xyz / c.w;
    float inside = (c.w > 0.0 && all(lessThan(abs(ndc), vec3(1.0)))) ? 1.0 : 0.0;
    return vec4(ndc * 0.5 + 0.5, inside);
}

// One hard shadow-map test: 1 where p is nearer the lamp than the caster depth
// stored for its texel. Outside the light's frustum: lit.
float shadowHard(sampler2D shadowMap, vec3 p, float bias) {
    vec4 ls = lightSpace(p);
    return ls.w == 0.0 || ls.z - bias <= texture(shadowMap, ls.xy).r ? 1.0 : 0.0;
}

// Fraction of the lamp that sees p: a percentage-closer filter through a comparison
// sampler (GL_LINEAR + GL_COMPARE_REF_TO_TEXTURE, GL_LEQUAL): KILN_PCF = k, (k+1)/2 ×
// (k+1)/2 bilinear blends of four depth tests each, two texels apart, a smooth filter
// about k+1 texels wide (5 → 9 over 6×6 texels, where a nearest-texel 5×5 box needs 25).
// The blends are whole texels apart, so they share their bilinear weights: each
// 2×2's four tests are gathered (textureGather on the comparison sampler), summed by
// their place in it, and blended once — the same filter (to rounding in `direct`), and
// a cheaper composite where many pixels are recomputed: llvmpipe's filtered lookup
// weighs its four tests itself, four times over.
// Unrolled: the kernel is a compile-time constant (on llvmpipe a loop with a uniform
// bound, and a branch around taps, cost more than the taps). Outside the light's
// frustum: lit.
#ifndef KILN_PCF
#define KILN_PCF 5
#endif
// `ls`: the point in the map (lightSpace: xy, z, w = 0 outside the frustum).
float shadowFilteredAt(sampler2DShadow shadowMap, vec4 ls, float bias) {
    const int n = (KILN_PCF + 1) / 2;
    vec2 size = vec2(textureSize(shadowMap, 0));
    vec2 texel = 1.0 / size;
    vec4 sum = vec4(0.0);  // the tests by place in each 2×2, gather's order: (0,1) (1,1) (1,0) (0,0)
    for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) {
            vec2 offset = (vec2(x, y) * 2.0 - float(n - 1)) * texel;
            sum += textureGather(shadowMap, ls.xy + offset, ls.z - bias);
        }
    vec2 f = fract(ls.xy * size - 0.5);  // where the blends sit between their texels' centres
    float lit = mix(mix(sum.w, sum.z, f.x), mix(sum.x, sum.y, f.x), f.y);
    return ls.w == 0.0 ? 1.0 : lit / float(n * n);
}

float shadowFiltered(sampler2DShadow shadowMap, vec3 p, float bias) {
    return shadowFilteredAt(shadowMap, lightSpace(p), bias);
}
