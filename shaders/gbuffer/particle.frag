#version 450 core
// A particle as a sphere seen from the camera: the disc of its silhouette, its
// emission. Only the emission is written (alpha 2: a particle hides the surface the
// G-buffer's other outputs keep; gbuffer.cpp), depth tested at the centre's depth: a
// particle spans a few pixels.
flat in vec3 v_emissive;

layout(location = 2) out vec4 o_emissive;

void main() {
    vec2 d = gl_PointCoord * 2.0 - 1.0;
    if (dot(d, d) > 1.0) discard;
    o_emissive = vec4(v_emissive, 2.0);
}
