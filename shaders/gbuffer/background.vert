#version 450 core
// The background (gbuffer.cpp): one triangle over the screen just before the far plane,
// drawn last with the depth test on and depth writes off, so it lands only where no
// geometry did.
#include "common/fullscreen.glsl"
void main() {
    // Window depth 1 − 2⁻²⁰ (0.999999): behind everything nearer than about 19.9 m of
    // the camera's 20 m far plane, in front of the cleared 1.
    gl_Position = vec4(fullscreenCorner() * 2.0 - 1.0, 1.0 - exp2(-19.0), 1.0);
}
