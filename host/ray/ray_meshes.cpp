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
    emitters_.clear();
    emittedPower_ = 0.0f;
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
        meshTriangles_.push_back({});
        return;
    }
    meshTriangles_.push_back({uint32_t(triangles_.size()), uint32_t(bvh.order.size())});
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
    emitters_.clear();
    emittedPower_ = 0.0f;
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
        if (!(s.emitted > 0.0f)) continue;
        const glm::mat3 linear(s.model);
        const Range r = meshTriangles_[s.mesh];
        for (uint32_t t = r.first; t < r.first + r.count; ++t) {
            const RayTriangle& tri = triangles_[t];
            const glm::vec3 e1 = linear * tri.e1, e2 = linear * tri.e2;
            const float power = 0.5f * glm::length(glm::cross(e1, e2)) * s.emitted;
            if (!(power > 0.0f)) continue;
            emittedPower_ += power;
            emitters_.push_back({glm::vec3(s.model * glm::vec4(tri.v0, 1.0f)), emittedPower_, e1,
                                 uint32_t(instances_.size() - 1), e2, t});
        }
    }
    // Running sums → shares: the last is 1 exactly, so a uniform number always lands.
    for (RayEmitter& e : emitters_) e.cdf /= emittedPower_;
    if (!emitters_.empty()) emitters_.back().cdf = 1.0f;
    topRoot_ = appendNodes(nodes_, bvh, 0);
}

}  // namespace kiln::ray
