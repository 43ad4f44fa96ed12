#include "ray/ray_meshes.hpp"

#include <glm/gtc/matrix_inverse.hpp>

namespace kiln::ray {

namespace {

// Appends `bvh`'s nodes to `nodes`, its children's indices moved by the nodes already
// there and its leaves' by `leafBase` (where its primitives start in their buffer).
uint32_t appendNodes(std::vector<BvhNode>& nodes, const Bvh& bvh, uint32_t leafBase) {
    const uint32_t base = uint32_t(nodes.size());
    for (BvhNode n : bvh.nodes) {
        n.first += n.count == 0 ? base : leafBase;
        nodes.push_back(n);
    }
    return base;
}

}  // namespace

void RayMeshData::addMesh(const RayMeshSource& mesh) {
    nodes_.resize(meshNodes_);  // a top level built before no longer holds
    instances_.clear();
    const size_t count = mesh.indices.size() / 3;
    std::vector<Aabb> bounds(count);
    Aabb all;
    for (size_t t = 0; t < count; ++t) {
        for (int k = 0; k < 3; ++k) bounds[t].grow(mesh.positions[mesh.indices[3 * t + size_t(k)]]);
        all.grow(bounds[t]);
    }
    const Bvh bvh = buildBvh(bounds);
    if (bvh.nodes.empty()) {
        meshRoots_.push_back(UINT32_MAX);
        meshBounds_.push_back({});
        return;
    }
    const uint32_t root = appendNodes(nodes_, bvh, uint32_t(triangles_.size()));
    for (uint32_t t : bvh.order) {
        const glm::vec3 a = mesh.positions[mesh.indices[3 * t]], b = mesh.positions[mesh.indices[3 * t + 1]],
                        c = mesh.positions[mesh.indices[3 * t + 2]];
        triangles_.push_back({a, mesh.firstIndex + 3 * t, b - a, root, c - a});
    }
    meshNodes_ = nodes_.size();
    meshRoots_.push_back(root);
    meshBounds_.push_back(all);
}

void RayMeshData::setInstances(std::span<const RayInstanceSource> sources) {
    nodes_.resize(meshNodes_);
    instances_.clear();
    std::vector<Aabb> bounds(sources.size());
    for (size_t i = 0; i < sources.size(); ++i)
        if (sources[i].mesh < meshRoots_.size() && meshRoots_[sources[i].mesh] != UINT32_MAX)
            bounds[i] = transformed(meshBounds_[sources[i].mesh], sources[i].model);
    const Bvh bvh = buildBvh(bounds, 2);
    if (bvh.nodes.empty()) return;
    for (uint32_t i : bvh.order) {
        const RayInstanceSource& s = sources[i];
        const glm::mat4 inverse = glm::affineInverse(s.model);
        const glm::mat4 rows = glm::transpose(inverse);
        instances_.push_back({{rows[0], rows[1], rows[2]}, meshRoots_[s.mesh], s.instance, s.baseVertex,
                              s.twoSided ? 1u : 0u});
    }
    topRoot_ = appendNodes(nodes_, bvh, 0);
}

}  // namespace kiln::ray
