#version 450 core
// The full-screen triangle (common/fullscreen.vert), collapsed to a point when
// bloom/bright.comp found no texel above the threshold: the pass has cleared its
// target to black, so nothing is drawn and no tap is taken. The flag is read here,
// once a vertex: read once a fragment it cost bloom 0.9 of its 6.9 ms at 720² on
// llvmpipe, where something is always bright.
#include "common/fullscreen.glsl"
layout(std430, binding = 1) readonly buffer AnyBright { uint u_anyBright; };

void main() {
    vec2 p = fullscreenCorner();
    gl_Position = u_anyBright == 0u ? vec4(0.0, 0.0, 0.0, 1.0) : vec4(p * 2.0 - 1.0, 0.0, 1.0);
}
