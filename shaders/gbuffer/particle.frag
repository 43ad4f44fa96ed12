#version 450 core
// A particle as a sphere seen from the camera: the disc of its silhouette, with the
// sphere's normal (in view space from gl_PointCoord, then to world), no albedo, its
// emission. Depth stays the centre's: a particle spans a few pixels.
#include "common/frame.glsl"

flat in vec3 v_albedo;
flat in vec3 v_emissive;

layout(location = 0) out vec4 o_albedo;
layout(location = 1) out vec4 o_normal;
layout(location = 2) out vec4 o_emissive;

void main() {
    vec2 d = gl_PointCoord * 2.0 - 1.0;
    d.y = -d.y;  // gl_PointCoord grows downwards
    float r2 = dot(d, d);
    if (r2 > 1.0) discard;
    vec3 nView = vec3(d, sqrt(1.0 - r2));
    o_albedo = vec4(v_albedo, 1.0);
    o_normal = vec4(normalize(transpose(mat3(u_view)) * nView), 1.0);
    o_emissive = vec4(v_emissive, 1.0);
}
