#version 450 core
// The voxel radiance seen through the camera at one mip level (the seed's figure):
// the ray through each pixel, clipped to the box, marched front to back.
#include "common/frame.glsl"
#include "common/voxels.glsl"

in vec2 v_uv;
layout(location = 0) out vec4 o_color;
uniform float u_lod;
uniform float u_exposure;

void main() {
    vec4 nearP = u_invViewProj * vec4(v_uv * 2.0 - 1.0, -1.0, 1.0);
    vec4 farP = u_invViewProj * vec4(v_uv * 2.0 - 1.0, 1.0, 1.0);
    vec3 o = nearP.xyz / nearP.w, d = normalize(farP.xyz / farP.w - o);
    vec3 inv = 1.0 / d;
    vec3 t0 = (-1.0 - o) * inv, t1 = (1.0 - o) * inv;
    float tNear = max(max(min(t0.x, t1.x), min(t0.y, t1.y)), min(t0.z, t1.z));
    float tFar = min(min(max(t0.x, t1.x), max(t0.y, t1.y)), max(t0.z, t1.z));
    vec3 color = vec3(0.0);
    float alpha = 0.0;
    float step_ = voxelSize() * exp2(u_lod) * 0.5;
    for (float t = max(tNear, 0.0); t < tFar && alpha < 0.98; t += step_) {
        vec4 s = sampleVoxels(o + d * t, d, u_lod);
        color += (1.0 - alpha) * s.rgb;
        alpha += (1.0 - alpha) * s.a;
    }
    vec3 c = color * u_exposure;
    o_color = vec4(pow(c / (1.0 + c), vec3(1.0 / 2.2)), 1.0);
}
