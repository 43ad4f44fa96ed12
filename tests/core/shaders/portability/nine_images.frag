#version 450 core
// Nine images in units 0-8 of a fragment shader: one unit and one image too many for
// OpenGL 4.5's guaranteed 8.
layout(r32ui, binding = 0) uniform uimage2D u_images[9];
out vec4 o_color;
void main() {
    uint sum = 0u;
    for (int i = 0; i < 9; ++i) sum += imageLoad(u_images[i], ivec2(gl_FragCoord.xy)).r;
    o_color = vec4(float(sum));
}
