#version 450 core
// Each tile of the picture to one of two lists: those moved_tiles.comp marked (or all,
// u_all) to draw with the lamp's light recomputed, the rest to draw from what was kept.
// Counts the marked tiles (composite.cpp reads the count a run later to choose how to
// draw) and resets the marks for the next run. The buffer starts with the two lists'
// draw commands (six vertices a tile, counted here) and the count; composite.cpp zeroes
// them first.
layout(local_size_x = 64) in;

layout(std430, binding = 2) buffer TileMarks { uint tileMarks[]; };
// [0,4) and [4,8) the commands, [8] the marked tiles, then the two lists from kListsStart.
layout(std430, binding = 3) buffer TileLists { uint tileLists[]; };
const uint kListsStart = 12u;
uniform uint u_tileCount;
uniform bool u_all;

void main() {
    uint tile = gl_GlobalInvocationID.x;
    if (tile >= u_tileCount) return;
    bool moved = tileMarks[tile] != 0u, recompute = u_all || moved;
    tileMarks[tile] = 0u;
    if (moved) atomicAdd(tileLists[8], 1u);
    uint slot = atomicAdd(tileLists[recompute ? 0u : 4u], 6u) / 6u;  // two triangles a tile
    tileLists[kListsStart + (recompute ? 0u : u_tileCount) + slot] = tile;
}
