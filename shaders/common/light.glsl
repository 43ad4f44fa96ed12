// The lamp's shadow projection, shared by the shadow pass and everything that reads
// its map. A perspective view from the lamp centre (above the ceiling, outside the
// box) looking straight down: one 2D map covers the box below the lamp (SPEC §6.2).
// 140° field of view: the floor and every caster are inside; the topmost corners of
// the walls (y > 0.85, receivers only, already shaded by the lamp's directional
// falloff) fall outside and read as lit.
#include "frame.glsl"

const float kLightNear = 0.05;
const float kLightFar = 3.5;

mat4 lightViewProj() {
    vec3 eye = u_lightPos.xyz;
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

// The lamp, defined once (scene file `lamp`): the part of the sphere u_lightPos (xyz
// centre, w radius) below the ceiling y = 1, a Lambertian emitter of radiance
// u_lightColor.rgb. Its irradiance at p on a surface with unit normal n, before
// visibility, is E = ∫_cap L · cos θ_p · cos θ_q / d² dA, here by a fixed
// KILN_LAMP_SAMPLES-point quadrature: equal-area points on the cap (a sphere's area is
// uniform in height, Archimedes) on a golden-angle spiral. The cap is convex, so its
// points facing p (cos θ_q > 0) are exactly the visible ones. Diffuse outgoing
// radiance = albedo/π · E · visibility. Shared by composite (PCF shadows) and voxelize
// (hard shadows); passes/reference samples the same emitter, so the rasterized frame
// and the reference agree on the lamp without a fudge factor.
#ifndef KILN_LAMP_SAMPLES
#define KILN_LAMP_SAMPLES 32
#endif
const float kCeilingY = 1.0;

vec3 lampLight(vec3 p, vec3 n) {
    const vec3 c = u_lightPos.xyz;
    const float radius = u_lightPos.w;
    const float yLow = c.y - radius, yHigh = min(kCeilingY, c.y + radius);
    if (yHigh <= yLow) return vec3(0.0);
    const float dy = (yHigh - yLow) / float(KILN_LAMP_SAMPLES);
    const vec2 turn = vec2(cos(2.39996323), sin(2.39996323));  // the golden angle
    vec2 dir = vec2(1.0, 0.0);
    float sum = 0.0;
    for (int i = 0; i < KILN_LAMP_SAMPLES; ++i) {
        const float h = yLow + (float(i) + 0.5) * dy - c.y;
        const vec3 nq = vec3(dir.x * sqrt(max(radius * radius - h * h, 0.0)), h, dir.y * sqrt(max(radius * radius - h * h, 0.0))) / radius;
        const vec3 w = c + nq * radius - p;
        const float d2 = dot(w, w);
        sum += max(dot(n, w), 0.0) * max(-dot(nq, w), 0.0) / (d2 * d2);
        dir = vec2(dir.x * turn.x - dir.y * turn.y, dir.x * turn.y + dir.y * turn.x);
    }
    const float area = 6.28318531 * radius * (yHigh - yLow);
    return u_lightColor.rgb * (sum * area / float(KILN_LAMP_SAMPLES));
}

// One hard shadow-map test: 1 where p is nearer the lamp than the caster depth
// stored for its texel. Outside the light's frustum: lit.
float shadowHard(sampler2D shadowMap, vec3 p, float bias) {
    vec4 ls = lightSpace(p);
    return ls.w == 0.0 || ls.z - bias <= texture(shadowMap, ls.xy).r ? 1.0 : 0.0;
}

// Fraction of the lamp that sees p: a percentage-closer filter through a comparison
// sampler (GL_LINEAR + GL_COMPARE_REF_TO_TEXTURE, GL_LEQUAL), so each lookup is
// already a bilinear blend of four depth tests. KILN_PCF = k: (k+1)/2 × (k+1)/2
// lookups two texels apart, a smooth filter about k+1 texels wide (5 → 9 lookups over
// 6×6 texels, where a nearest-texel 5×5 box needs 25). Unrolled: the kernel is a
// compile-time constant (on llvmpipe a loop with a uniform bound, and a branch around
// taps, cost more than the taps). Outside the light's frustum: lit.
#ifndef KILN_PCF
#define KILN_PCF 5
#endif
float shadowFiltered(sampler2DShadow shadowMap, vec3 p, float bias) {
    vec4 ls = lightSpace(p);
    const int n = (KILN_PCF + 1) / 2;
    vec2 texel = 1.0 / vec2(textureSize(shadowMap, 0));
    float lit = 0.0;
    for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) {
            vec2 offset = (vec2(x, y) * 2.0 - float(n - 1)) * texel;
            lit += texture(shadowMap, vec3(ls.xy + offset, ls.z - bias));
        }
    return ls.w == 0.0 ? 1.0 : lit / float(n * n);
}
