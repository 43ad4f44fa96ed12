// ray/bvh.hpp — bounding volume hierarchies for tracing rays through the placed
// meshes: built on the CPU by binned SAH, flattened into the node layout the shaders
// read (shaders/common/ray_meshes.glsl). One hierarchy per mesh over its triangles and
// one over the instances, so a moved instance costs a rebuild of the small top level.
#pragma once

#include <cstdint>
#include <limits>
#include <span>
#include <vector>

#include <glm/glm.hpp>

namespace kiln::ray {

struct Aabb {
    glm::vec3 lo{std::numeric_limits<float>::infinity()};
    glm::vec3 hi{-std::numeric_limits<float>::infinity()};
    void grow(const glm::vec3& p) { lo = glm::min(lo, p), hi = glm::max(hi, p); }
    void grow(const Aabb& b) { lo = glm::min(lo, b.lo), hi = glm::max(hi, b.hi); }
    bool empty() const { return lo.x > hi.x || lo.y > hi.y || lo.z > hi.z; }
    glm::vec3 centre() const { return 0.5f * (lo + hi); }
    // Half the surface area (what SAH compares; the factor 2 cancels).
    float halfArea() const {
        if (empty()) return 0.0f;
        const glm::vec3 e = hi - lo;
        return e.x * e.y + e.y * e.z + e.z * e.x;
    }
};

// A node as the shaders read it (std430: two vec4). An interior node (count 0) has its
// children at nodes[first] and nodes[first + 1]; a leaf holds the primitives
// order[first .. first + count).
struct BvhNode {
    glm::vec3 lo;
    uint32_t first;
    glm::vec3 hi;
    uint32_t count;
};
static_assert(sizeof(BvhNode) == 32);

struct Bvh {
    std::vector<BvhNode> nodes;   // nodes[0] is the root; empty when there are no primitives
    std::vector<uint32_t> order;  // primitive indices in leaf order
};

// The deepest a hierarchy goes (edges from the root to a leaf): the shaders walk it
// nearest child first with a stack of this many entries, one pushed per level
// (shaders/common/ray_meshes.glsl), so a deeper tree would lose what lay past it.
inline constexpr uint32_t kMaxBvhDepth = 48;

// Binned SAH (16 bins on each axis): a node is split where the surface-area cost is
// least, and becomes a leaf when no split is cheaper than testing its primitives, at
// most `maxLeaf` of them (a node of more whose primitives' centres coincide is split
// in the middle of the list, so no leaf grows without bound on degenerate input).
// Primitives with empty bounds are left out. No leaf lies deeper than `maxDepth`: where
// the SAH's cuts would take a subtree past it, the node is split at the median along
// its centres' longest axis instead (so what is left halves to leaves of `maxLeaf` in
// the levels left), and a node at `maxDepth` is a leaf whatever its count.
Bvh buildBvh(std::span<const Aabb> bounds, uint32_t maxLeaf = 4, uint32_t maxDepth = kMaxBvhDepth);

// The bounds of `box` moved by the affine transform `m` (its eight corners').
Aabb transformed(const Aabb& box, const glm::mat4& m);

}  // namespace kiln::ray
