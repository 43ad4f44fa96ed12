#include "ray/volume_faces.hpp"

namespace kiln::ray {

uint32_t closedVolumeFaces(const RayMeshData& meshes, glm::vec3 centre, glm::vec3 half, glm::vec3 lo, glm::vec3 hi,
                           glm::vec3 depth, int grid, float share) {
    if (meshes.instances().empty() || grid < 1) return 0;
    uint32_t closed = 0;
    for (int axis = 0; axis < 3; ++axis)
        for (int side = 0; side < 2; ++side) {
            const int u = (axis + 1) % 3, v = (axis + 2) % 3;
            const float outward = side == 0 ? -1.0f : 1.0f;
            int met = 0;
            for (int i = 0; i < grid; ++i)
                for (int j = 0; j < grid; ++j) {
                    glm::vec3 origin = centre;
                    // Cell centres, so no ray runs along an edge of the volume.
                    origin[u] = lo[u] + (hi[u] - lo[u]) * (float(i) + 0.5f) / float(grid);
                    origin[v] = lo[v] + (hi[v] - lo[v]) * (float(j) + 0.5f) / float(grid);
                    origin[axis] += outward * (half[axis] + depth[axis]);
                    glm::vec3 inward(0.0f);
                    inward[axis] = -outward;
                    met += meshes.nearestHit(origin, inward, 2.0f * depth[axis], false).found() ? 1 : 0;
                }
            if (float(met) >= share * float(grid * grid)) closed |= 1u << (2 * axis + side);
        }
    return closed;
}

}  // namespace kiln::ray
