#version 450 core
// One triangle covering the screen (drawFullscreenTriangle: 3 vertices, no buffers).
#include "fullscreen.glsl"
out vec2 v_uv;
void main() {
    vec2 p = fullscreenCorner();
    v_uv = p;
    gl_Position = vec4(p * 2.0 - 1.0, 0.0, 1.0);
}
