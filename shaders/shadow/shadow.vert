#version 450 core
// Depth from the lamp (common/light.glsl) of the shadow casters.
#include "common/scene.glsl"
#include "common/shadow.glsl"

void main() {
    gl_Position = lightViewProj() * (kilnInstance().model * vec4(a_position, 1.0));
}
