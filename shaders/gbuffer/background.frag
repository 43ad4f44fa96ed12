#version 450 core
// Where no geometry is: albedo, normal (w = 0: no surface) and emission all zero, what
// the colour clears wrote before (gbuffer.cpp says why it is drawn instead).
layout(location = 0) out vec4 o_albedo;
layout(location = 1) out vec4 o_normal;
layout(location = 2) out vec4 o_emissive;
void main() {
    o_albedo = vec4(0.0);
    o_normal = vec4(0.0);
    o_emissive = vec4(0.0);
}
