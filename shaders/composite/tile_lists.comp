#version 450 core
// Each tile of the picture to one of two lists: those moved_tiles.comp marked (or all,
// u_all) to draw with the lamp's light recomputed, the rest to draw from the cache.
// Resets the marks for the next run. The two lists' draw commands (six vertices a tile,
// counted here; one instance: llvmpipe runs a draw's instances one by one) head the
// buffer; composite.cpp zeroes their counts first.
layout(local_size_x = 64) in;

layout(std430, binding = 2) buffer TileMarks { uint tileMarks[]; };
layout(std430, binding = 3) buffer TileLists { uint tileLists[]; };  // [0,4) [4,8) commands, then the lists
uniform uint u_tileCount;
uniform bool u_all;

void main() {
    uint tile = gl_GlobalInvocationID.x;
    if (tile >= u_tileCount) return;
    bool marked = u_all || tileMarks[tile] != 0u;
    tileMarks[tile] = 0u;
    uint command = marked ? 0u : 4u;
    uint slot = atomicAdd(tileLists[command], 6u) / 6u;  // two triangles a tile
    tileLists[8u + (marked ? 0u : u_tileCount) + slot] = tile;
}
