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
