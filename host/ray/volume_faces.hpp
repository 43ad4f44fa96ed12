// ray/volume_faces.hpp — which faces of the voxel volume the scene's own surfaces close:
// where a wall lies in the volume's outermost layer, a cone lookup past that face should
// see the wall continue (its voxels clamped), not empty space, or a room's coarse
// lookups lose much of their light to the empty border (GpuFrame::closedFaces).
#pragma once

#include <cstdint>

#include <glm/glm.hpp>

#include "ray/ray_meshes.hpp"

namespace kiln::ray {

// Each face of the box `centre` ± `half`, tested over the part of it the scene's bounds
// [lo, hi] cover (beyond them its outermost voxels are empty, and an empty voxel clamped
// is empty space all the same) by a grid of `grid` × `grid` rays cast from just outside
// it inward, either side of a triangle counting: closed when at least `share` of them
// meet a triangle within `depth[a]` of a face across axis a. Bit 2a for the face at
// −axis a, 2a + 1 for +axis a (GpuFrame::closedFaces.x).
uint32_t closedVolumeFaces(const RayMeshData& meshes, glm::vec3 centre, glm::vec3 half, glm::vec3 lo, glm::vec3 hi,
                           glm::vec3 depth, int grid = 16, float share = 0.9f);

}  // namespace kiln::ray
