#version 450 core
// lamp_model `field` (composite, voxelize): the lamp's vector irradiance ÷ its radiance
// (common/light.glsl lampVector), stored on a 2D grid. The lamp is a ball cut by the
// horizontal ceiling, so it is symmetric about the vertical line through its centre,
// and so is F: at a point ρ from that axis and at height y, F = F_ρ(ρ, y) ρ̂ + F_y(ρ, y) ŷ.
// The grid holds (F_ρ, F_y) at ρ = ρ_max i/(N − 1), y = −1 + 2j/(N − 1) (ρ_max: the
// box's farthest vertical edge, lampFieldRadius; the floor and ceiling lie on nodes).
// One bilinear lookup a pixel where a 3D grid took a trilinear one, and N² nodes
// instead of N³. Built when the lamp changes.
#include "common/light.glsl"
#include "common/lamp_field.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(rg16f, binding = 0) uniform writeonly image2D u_field;

void main() {
    ivec2 node = ivec2(gl_GlobalInvocationID.xy);
    ivec2 n = imageSize(u_field);
    if (any(greaterThanEqual(node, n))) return;
    vec2 rhoY = vec2(node) / vec2(n - 1) * vec2(lampFieldRadius(), 2.0) - vec2(0.0, 1.0);
    // Along +x from the axis: there ρ̂ = x̂.
    vec3 f = lampVector(vec3(u_lightPos.x + rhoY.x, rhoY.y, u_lightPos.z));
    imageStore(u_field, node, vec4(f.x, f.y, 0.0, 0.0));
}
