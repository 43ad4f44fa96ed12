#version 450 core
// Two triangles (six vertices) a tile of u_tileSize² pixels, the tiles of a list:
// composite.cpp draws the pixels whose lamp light must be recomputed, and the rest, as
// two lists of tiles (glDrawArraysIndirect).
#include "common/frame.glsl"

// The lists as a buffer texture, not a storage block: GL 4.5 need not offer storage
// blocks to a vertex shader.
layout(binding = 10) uniform usamplerBuffer u_tileLists;
uniform uint u_listStart;   // where this draw's list begins in u_tileLists
uniform int u_tileSize;
uniform int u_tilesAcross;

void main() {
    uint tile = texelFetch(u_tileLists, int(u_listStart) + gl_VertexID / 6).r;
    const ivec2 kCorners[6] = ivec2[](ivec2(0, 0), ivec2(1, 0), ivec2(0, 1), ivec2(0, 1), ivec2(1, 0), ivec2(1, 1));
    ivec2 corner = kCorners[gl_VertexID % 6];
    vec2 pixel = vec2((ivec2(int(tile) % u_tilesAcross, int(tile) / u_tilesAcross) + corner) * u_tileSize);
    gl_Position = vec4(pixel * u_outputSize.zw * 2.0 - 1.0, 0.0, 1.0);
}
