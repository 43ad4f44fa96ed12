#version 450 core
// The debug view's texture display: channel selection, range remap, exposure,
// depth linearisation, mip level and, for 3D textures, a slice along an axis.
in vec2 v_uv;
out vec4 o_color;
layout(binding = 0) uniform sampler2D u_tex2d;
layout(binding = 1) uniform sampler3D u_tex3d;
uniform bool u_is3d;
uniform bool u_isInteger;
uniform int u_channel;       // 0 RGB, 1 R, 2 G, 3 B, 4 A
uniform vec2 u_range;
uniform float u_exposure;
uniform bool u_linearizeDepth;
uniform float u_mip;
uniform float u_slice;
uniform int u_axis;

void main() {
    vec4 v;
    if (u_is3d) {
        vec3 p = u_axis == 0 ? vec3(u_slice, v_uv) : u_axis == 1 ? vec3(v_uv.x, u_slice, v_uv.y) : vec3(v_uv, u_slice);
        v = textureLod(u_tex3d, p, u_mip);
    } else {
        v = textureLod(u_tex2d, v_uv, u_mip);
    }
    if (u_linearizeDepth) {
        // The host camera's near/far (app/camera.cpp): 0.05 .. 20.
        float n = 0.05, f = 20.0, z = v.r * 2.0 - 1.0;
        float linear = 2.0 * n * f / (f + n - z * (f - n));
        v = vec4(vec3(linear / 5.0), 1.0);
    }
    vec3 c = u_channel == 0 ? v.rgb : vec3(v[u_channel - 1]);
    c = (c * u_exposure - u_range.x) / max(u_range.y - u_range.x, 1e-6);
    o_color = vec4(clamp(c, 0.0, 1.0), 1.0);
}
