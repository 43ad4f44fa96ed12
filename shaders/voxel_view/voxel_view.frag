#version 450 core
// Ray-march the voxels at one mip level: a 3D DDA (Amanatides & Woo) over the level's
// grid over the voxel volume (in grid space, [-1,1]³), compositing premultiplied colour front to back until opaque.
#include "common/frame.glsl"

in vec2 v_uv;
layout(location = 0) out vec4 o_color;
layout(binding = 0) uniform sampler3D u_voxels;
uniform int u_mip;
uniform float u_exposure;
uniform float u_minOpacity;

void main() {
    vec4 nearP = u_invViewProj * vec4(v_uv * 2.0 - 1.0, -1.0, 1.0);
    vec4 farP = u_invViewProj * vec4(v_uv * 2.0 - 1.0, 1.0, 1.0);
    vec3 ro = kilnWorldToGrid(nearP.xyz / nearP.w);
    vec3 rd = normalize(kilnWorldToGrid(farP.xyz / farP.w) - ro);
    vec3 inv = 1.0 / rd;
    vec3 t0 = (vec3(-1.0) - ro) * inv, t1 = (vec3(1.0) - ro) * inv;
    float tEnter = max(max(min(t0.x, t1.x), min(t0.y, t1.y)), max(min(t0.z, t1.z), 0.0));
    float tExit = min(min(max(t0.x, t1.x), max(t0.y, t1.y)), max(t0.z, t1.z));
    vec4 acc = vec4(0.0);
    if (tEnter < tExit) {
        ivec3 n = textureSize(u_voxels, u_mip);
        vec3 cell = 2.0 / vec3(n);
        vec3 p = ro + rd * (tEnter + 1e-4);
        ivec3 c = clamp(ivec3(floor((p + 1.0) / cell)), ivec3(0), n - 1);
        ivec3 stepDir = ivec3(sign(rd));
        vec3 next = (vec3(c + max(stepDir, ivec3(0))) * cell - 1.0 - ro) * inv;
        vec3 delta = abs(cell * inv);
        for (int i = 0; i < 3 * 256 && acc.a < 0.99; ++i) {
            if (any(lessThan(c, ivec3(0))) || any(greaterThanEqual(c, n))) break;
            vec4 s = texelFetch(u_voxels, c, u_mip);
            if (s.a > u_minOpacity) {
                // Show the voxel's own colour (un-premultiplied) as a solid box.
                acc.rgb += (1.0 - acc.a) * s.rgb / s.a;
                acc.a = 1.0;
            }
            if (next.x < next.y && next.x < next.z) { c.x += stepDir.x; next.x += delta.x; }
            else if (next.y < next.z) { c.y += stepDir.y; next.y += delta.y; }
            else { c.z += stepDir.z; next.z += delta.z; }
        }
    }
    vec3 x = acc.rgb * u_exposure;
    vec3 mapped = clamp((x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14), 0.0, 1.0);
    o_color = vec4(pow(mapped, vec3(1.0 / 2.2)), 1.0);
}
