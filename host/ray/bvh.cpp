#include "ray/bvh.hpp"

#include <algorithm>
#include <array>

namespace kiln::ray {

namespace {

constexpr int kBins = 16;
// Cost of visiting a node relative to testing one primitive.
constexpr float kTraversalCost = 1.0f;
// A leaf of this many primitives whose centres coincide is split anyway (by the list).
constexpr uint32_t kForcedSplitAbove = 64;

struct Split {
    int axis = -1;
    float position = 0.0f;
    float cost = std::numeric_limits<float>::infinity();
};

Split bestSplit(std::span<const Aabb> bounds, const uint32_t* begin, const uint32_t* end, const Aabb& centres) {
    Split best;
    for (int axis = 0; axis < 3; ++axis) {
        const float lo = centres.lo[axis], extent = centres.hi[axis] - lo;
        if (!(extent > 0.0f)) continue;
        const float scale = float(kBins) / extent;
        std::array<Aabb, kBins> box{};
        std::array<uint32_t, kBins> count{};
        for (const uint32_t* p = begin; p != end; ++p) {
            const Aabb& b = bounds[*p];
            const int bin = std::min(kBins - 1, int((b.centre()[axis] - lo) * scale));
            box[size_t(bin)].grow(b);
            ++count[size_t(bin)];
        }
        // Sweep from the right, then from the left: cost of splitting after bin i.
        std::array<float, kBins - 1> rightCost{};
        Aabb right;
        uint32_t rightCount = 0;
        for (int i = kBins - 1; i > 0; --i) {
            right.grow(box[size_t(i)]);
            rightCount += count[size_t(i)];
            rightCost[size_t(i - 1)] = right.halfArea() * float(rightCount);
        }
        Aabb left;
        uint32_t leftCount = 0;
        for (int i = 0; i < kBins - 1; ++i) {
            left.grow(box[size_t(i)]);
            leftCount += count[size_t(i)];
            if (leftCount == 0 || leftCount == uint32_t(end - begin)) continue;
            const float cost = left.halfArea() * float(leftCount) + rightCost[size_t(i)];
            if (cost < best.cost) best = {axis, lo + float(i + 1) / scale, cost};
        }
    }
    return best;
}

}  // namespace

Bvh buildBvh(std::span<const Aabb> bounds, uint32_t maxLeaf, uint32_t maxDepth) {
    Bvh bvh;
    bvh.order.reserve(bounds.size());
    for (uint32_t i = 0; i < uint32_t(bounds.size()); ++i)
        if (!bounds[i].empty()) bvh.order.push_back(i);
    if (bvh.order.empty()) return bvh;
    maxLeaf = std::max(1u, maxLeaf);
    bvh.nodes.reserve(2 * bvh.order.size() / std::min<size_t>(maxLeaf, 2) + 1);
    bvh.nodes.push_back({glm::vec3(0.0f), 0, glm::vec3(0.0f), uint32_t(bvh.order.size())});

    struct Task { uint32_t node, first, count, depth; };
    std::vector<Task> tasks{{0, 0, uint32_t(bvh.order.size()), 0}};
    // Makes task's node an interior one over two new nodes: its first leftCount
    // primitives and the rest.
    auto pushChildren = [&](const Task& task, uint32_t leftCount) {
        const uint32_t children = uint32_t(bvh.nodes.size());
        bvh.nodes[task.node].first = children;
        bvh.nodes[task.node].count = 0;
        bvh.nodes.push_back({});
        bvh.nodes.push_back({});
        tasks.push_back({children, task.first, leftCount, task.depth + 1});
        tasks.push_back({children + 1, task.first + leftCount, task.count - leftCount, task.depth + 1});
    };
    while (!tasks.empty()) {
        const Task task = tasks.back();
        tasks.pop_back();
        uint32_t* begin = bvh.order.data() + task.first;
        uint32_t* end = begin + task.count;
        Aabb box, centres;
        for (const uint32_t* p = begin; p != end; ++p) box.grow(bounds[*p]), centres.grow(bounds[*p].centre());
        BvhNode& node = bvh.nodes[task.node];
        node = {box.lo, task.first, box.hi, task.count};
        if (task.count <= 1 || task.depth >= maxDepth) continue;

        // Halvings from here to leaves of maxLeaf; once they need every level left,
        // median splits keep the subtree within maxDepth.
        uint32_t halvings = 0;
        while ((uint64_t(maxLeaf) << halvings) < task.count) ++halvings;
        if (halvings >= maxDepth - task.depth) {
            const glm::vec3 extent = centres.hi - centres.lo;
            const int axis = extent.x >= extent.y && extent.x >= extent.z ? 0 : (extent.y >= extent.z ? 1 : 2);
            uint32_t* median = begin + task.count / 2;
            std::nth_element(begin, median, end, [&](uint32_t a, uint32_t b) {
                return bounds[a].centre()[axis] < bounds[b].centre()[axis];
            });
            pushChildren(task, uint32_t(median - begin));
            continue;
        }

        const Split split = bestSplit(bounds, begin, end, centres);
        const float leafCost = float(task.count);
        const float splitCost = kTraversalCost + split.cost / box.halfArea();
        uint32_t* middle = nullptr;
        if (split.axis >= 0 && (splitCost < leafCost || task.count > maxLeaf)) {
            middle = std::partition(begin, end, [&](uint32_t i) {
                return bounds[i].centre()[split.axis] < split.position;
            });
            if (middle == begin || middle == end) middle = nullptr;  // rounding put all on one side
        }
        if (!middle) {
            if (task.count <= std::max(maxLeaf, split.axis < 0 ? kForcedSplitAbove : maxLeaf)) continue;
            middle = begin + task.count / 2;  // coincident centres: split the list
        }
        pushChildren(task, uint32_t(middle - begin));
    }
    return bvh;
}

Aabb transformed(const Aabb& box, const glm::mat4& m) {
    Aabb out;
    if (box.empty()) return out;
    for (int corner = 0; corner < 8; ++corner) {
        const glm::vec3 p(corner & 1 ? box.hi.x : box.lo.x, corner & 2 ? box.hi.y : box.lo.y,
                          corner & 4 ? box.hi.z : box.lo.z);
        out.grow(glm::vec3(m * glm::vec4(p, 1.0f)));
    }
    return out;
}

}  // namespace kiln::ray
