#version 450 core
// The floor's wood grain (common/wood.glsl) baked into a texture over the floor's
// [-1,1]² in x and z, one invocation per texel centre; the gbuffer pass builds its
// mips and samples it, and re-bakes only when the scene's wood colours change.
#include "common/frame.glsl"
#include "common/wood.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0, rgba8) uniform writeonly image2D u_wood;

void main() {
    ivec2 size = imageSize(u_wood);
    ivec2 t = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(t, size))) return;
    vec2 xz = (vec2(t) + 0.5) / vec2(size) * 2.0 - 1.0;
    imageStore(u_wood, t, vec4(woodGrain(vec3(xz.x, -1.0, xz.y)), 1.0));
}
