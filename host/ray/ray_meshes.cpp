#include "ray/ray_meshes.hpp"

#include <algorithm>

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

// The slab test: where the ray enters the box within (tMin, tMax), or tMax if it misses.
float boxEntry(glm::vec3 o, glm::vec3 invD, const BvhNode& n, float tMin, float tMax) {
    const glm::vec3 a = (n.lo - o) * invD, b = (n.hi - o) * invD;
    const glm::vec3 near = glm::min(a, b), far = glm::max(a, b);
    const float enter = std::max(std::max(near.x, near.y), std::max(near.z, tMin));
    const float leave = std::min(std::min(far.x, far.y), std::min(far.z, tMax));
    return enter <= leave ? enter : tMax;
}

// Visits the leaves of the hierarchy at `root` whose boxes the ray enters before `tMax()`
// (read again after each leaf, as hits shorten it), nearer children first.
template <class Leaf, class Limit>
void walk(const std::vector<BvhNode>& nodes, uint32_t root, glm::vec3 o, glm::vec3 d, Limit tMax, Leaf leaf) {
    const glm::vec3 invD = 1.0f / d;
    if (boxEntry(o, invD, nodes[root], 0.0f, tMax()) >= tMax()) return;
    std::vector<uint32_t> stack;
    uint32_t node = root;
    while (true) {
        const BvhNode& n = nodes[node];
        if (n.count == 0) {
            const float ta = boxEntry(o, invD, nodes[n.first], 0.0f, tMax());
            const float tb = boxEntry(o, invD, nodes[n.first + 1], 0.0f, tMax());
            const bool inA = ta < tMax(), inB = tb < tMax();
            if (inA || inB) {
                const bool aFirst = inA && (!inB || ta <= tb);
                if (inA && inB) stack.push_back(aFirst ? n.first + 1 : n.first);
                node = aFirst ? n.first : n.first + 1;
                continue;
            }
        } else {
            leaf(n);
        }
        if (stack.empty()) return;
        node = stack.back();
        stack.pop_back();
    }
}

}  // namespace

RayHit RayMeshData::nearestHit(glm::vec3 o, glm::vec3 d, float tMax, bool oneSided) const {
    RayHit hit;
    hit.t = tMax;
    if (instances_.empty()) return hit;
    auto limit = [&] { return hit.t; };
    walk(nodes_, topRoot_, o, d, limit, [&](const BvhNode& top) {
        for (uint32_t k = top.first; k < top.first + top.count; ++k) {
            const RayInstance& ri = instances_[k];
            const glm::vec4 o1(o, 1.0f), d0(d, 0.0f);
            const glm::vec3 lo(glm::dot(ri.worldToLocal[0], o1), glm::dot(ri.worldToLocal[1], o1),
                               glm::dot(ri.worldToLocal[2], o1));
            const glm::vec3 ld(glm::dot(ri.worldToLocal[0], d0), glm::dot(ri.worldToLocal[1], d0),
                               glm::dot(ri.worldToLocal[2], d0));
            walk(nodes_, ri.root, lo, ld, limit, [&](const BvhNode& leaf) {
                for (uint32_t t = leaf.first; t < leaf.first + leaf.count; ++t) {
                    const RayTriangle& tri = triangles_[t];
                    const glm::vec3 p = glm::cross(ld, tri.e2);
                    const float det = glm::dot(tri.e1, p);
                    if (std::abs(det) < 1e-20f || (oneSided && ri.twoSided == 0 && det < 0.0f)) continue;
                    const float inv = 1.0f / det;
                    const glm::vec3 s = lo - tri.v0;
                    const float u = glm::dot(s, p) * inv;
                    if (u < 0.0f || u > 1.0f) continue;
                    const glm::vec3 q = glm::cross(s, tri.e1);
                    const float v = glm::dot(ld, q) * inv;
                    if (v < 0.0f || u + v > 1.0f) continue;
                    const float tt = glm::dot(tri.e2, q) * inv;
                    if (tt <= 0.0f || tt >= hit.t) continue;
                    hit = {tt, k, t, {u, v}};
                }
            });
        }
    });
    return hit;
}

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
