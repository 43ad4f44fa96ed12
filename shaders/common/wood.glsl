// A procedural wood grain for the floor: growth rings around a log axis running
// along x below the floor, warped by value noise, between the scene file's light and
// dark wood colours (u_ringsLight, u_ringsDark from common/frame.glsl; include it first).
// The lattice point's hash from integer arithmetic alone (a two-round permuted
// congruential mix), so every driver bakes the same grain: fract(sin(x) * 43758.5) at
// x in the hundreds rests on each driver's sin there, and NVIDIA's floor differed from
// llvmpipe's by a whole pattern. 24 bits, so the float is exact and below 1.
float kilnHash(vec2 p) {
    uvec2 v = uvec2(ivec2(p)) * 1664525u + 1013904223u;
    v.x += v.y * 1664525u;
    v.y += v.x * 1664525u;
    v ^= v >> 16u;
    v.x += v.y * 1664525u;
    v.y += v.x * 1664525u;
    v ^= v >> 16u;
    return float(v.x >> 8u) * (1.0 / 16777216.0);
}
float kilnNoise(vec2 p) {
    vec2 i = floor(p), f = fract(p);
    vec2 u = f * f * (3.0 - 2.0 * f);
    return mix(mix(kilnHash(i), kilnHash(i + vec2(1, 0)), u.x), mix(kilnHash(i + vec2(0, 1)), kilnHash(i + vec2(1, 1)), u.x), u.y);
}
vec3 woodGrain(vec3 world) {
    vec2 p = world.xz;
    float warp = kilnNoise(p * vec2(1.5, 6.0)) * 0.6 + kilnNoise(p * vec2(6.0, 24.0)) * 0.15;
    float r = length(vec2(p.y * 3.0, 1.7)) * u_ringsLight.w + warp * 3.0 + p.x * 0.8;
    float ring = smoothstep(0.0, 0.6, abs(fract(r) - 0.5) * 2.0);
    return mix(u_ringsDark.rgb, u_ringsLight.rgb, ring);
}
