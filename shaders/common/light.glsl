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

// Light arriving from the lamp at a surface point p with unit normal n, before
// visibility: u_lightColor · cos θ · the seed's "directional" falloff (the lamp is a
// hemisphere opening downwards, so light leaving it at a grazing angle to −y is
// dimmer and the wall tops get shade). Diffuse outgoing radiance = albedo/π · this ·
// visibility. Shared by composite (with PCF) and voxelize (hard shadow), so the
// voxels and the screen agree on the direct light.
vec3 lampLight(vec3 p, vec3 n) {
    vec3 l = normalize(u_lightPos.xyz - p);
    float cosTheta = max(dot(n, l), 0.0);
    float directional = smoothstep(0.0, 1.0, clamp(dot(-l, vec3(0.0, -1.0, 0.0)), 0.0, 1.0));
    return u_lightColor.rgb * cosTheta * directional;
}

// Fraction of the lamp that sees p through a shadow map of the casters: a k×k
// percentage-closer filter (k = 1: one hard test). Outside the light's frustum: lit.
// The four corner taps go first: when they agree (far from any shadow edge, most of
// the picture) the answer is theirs and the other k²−4 taps are skipped.
float shadowVisibility(sampler2D shadowMap, vec3 p, int k, float bias) {
    vec4 ls = lightSpace(p);
    if (ls.w == 0.0) return 1.0;
    vec2 texel = 1.0 / vec2(textureSize(shadowMap, 0));
    int r = k / 2;
    float z = ls.z - bias;
    if (r > 0) {
        float c = (z <= texture(shadowMap, ls.xy + vec2(-r, -r) * texel).r ? 1.0 : 0.0)
                + (z <= texture(shadowMap, ls.xy + vec2(r, -r) * texel).r ? 1.0 : 0.0)
                + (z <= texture(shadowMap, ls.xy + vec2(-r, r) * texel).r ? 1.0 : 0.0)
                + (z <= texture(shadowMap, ls.xy + vec2(r, r) * texel).r ? 1.0 : 0.0);
        if (c == 0.0 || c == 4.0) return c * 0.25;
    }
    float lit = 0.0;
    for (int y = -r; y <= r; ++y)
        for (int x = -r; x <= r; ++x)
            lit += (z <= texture(shadowMap, ls.xy + vec2(x, y) * texel).r) ? 1.0 : 0.0;
    return lit / float((2 * r + 1) * (2 * r + 1));
}
