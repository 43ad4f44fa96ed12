#version 450 core
// Depth from punctual light u_light (GpuFrame::punctual) into its tile of the atlas.
#include "common/scene.glsl"

uniform int u_light;

void main() {
    gl_Position = u_punctual[u_light].shadowViewProj * (kilnInstance().model * vec4(a_position, 1.0));
}
