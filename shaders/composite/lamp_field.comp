#version 450 core
// composite's lamp_model `field`: the lamp's vector irradiance ÷ its radiance
// (common/light.glsl lampVector) at the nodes of an N³ grid over the box [-1,1]³, node
// i at −1 + 2i/(N − 1) (the walls lie on nodes: no extrapolation there). Built when
// the lamp changes; a pixel then reads Φ = max(n·F, 0) with one trilinear lookup.
#include "common/light.glsl"

layout(local_size_x = 4, local_size_y = 4, local_size_z = 4) in;
layout(rgba16f, binding = 0) uniform writeonly image3D u_field;

void main() {
    ivec3 node = ivec3(gl_GlobalInvocationID);
    int n = imageSize(u_field).x;
    if (any(greaterThanEqual(node, ivec3(n)))) return;
    vec3 p = vec3(node) / float(n - 1) * 2.0 - 1.0;
    imageStore(u_field, node, vec4(lampVector(p), 0.0));
}
