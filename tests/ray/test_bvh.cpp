// The ray tracing hierarchies (host/ray): every triangle in one leaf, every box holding
// what lies below it, and the nearest hit found through both levels equal to testing
// every triangle of every instance — through RayMeshData::nearestHit, the walk and triangle
// test of the shaders (ray_meshes.glsl) on the CPU.
#include <catch2/catch.hpp>

#include <cmath>
#include <random>

#include <glm/gtc/matrix_transform.hpp>

#include "ray/bvh.hpp"
#include "ray/ray_meshes.hpp"

using namespace kiln::ray;

namespace {

struct Soup {
    std::vector<glm::vec3> positions;
    std::vector<uint32_t> indices;
};

// `count` triangles of up to `size` across, scattered in [-1, 1]³.
Soup randomSoup(int count, float size, uint32_t seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(-1.0f, 1.0f);
    Soup s;
    for (int t = 0; t < count; ++t) {
        const glm::vec3 c(u(rng), u(rng), u(rng));
        for (int k = 0; k < 3; ++k) {
            s.indices.push_back(uint32_t(s.positions.size()));
            s.positions.push_back(c + size * glm::vec3(u(rng), u(rng), u(rng)));
        }
    }
    return s;
}

bool contains(const Aabb& outer, const Aabb& inner) {
    return glm::all(glm::lessThanEqual(outer.lo, inner.lo)) && glm::all(glm::greaterThanEqual(outer.hi, inner.hi));
}

Aabb boxOf(const BvhNode& n) { return {n.lo, n.hi}; }

// Möller–Trumbore, as the shader does it; no culling. t in (tMin, tMax) or -1.
float hitTriangle(glm::vec3 o, glm::vec3 d, glm::vec3 v0, glm::vec3 e1, glm::vec3 e2, float tMax) {
    const glm::vec3 p = glm::cross(d, e2);
    const float det = glm::dot(e1, p);
    if (std::abs(det) < 1e-20f) return -1.0f;
    const float inv = 1.0f / det;
    const glm::vec3 s = o - v0;
    const float u = glm::dot(s, p) * inv;
    if (u < 0.0f || u > 1.0f) return -1.0f;
    const glm::vec3 q = glm::cross(s, e1);
    const float v = glm::dot(d, q) * inv;
    if (v < 0.0f || u + v > 1.0f) return -1.0f;
    const float t = glm::dot(e2, q) * inv;
    return t > 0.0f && t < tMax ? t : -1.0f;
}

struct Found {
    float t = INFINITY;
    uint32_t instance = UINT32_MAX;  // RayInstance::instance
    uint32_t firstIndex = 0;         // the triangle's
};

// Both levels, as RayMeshData::nearestHit walks them (the shaders' walk on the CPU).
Found traceHierarchy(const RayMeshData& data, glm::vec3 o, glm::vec3 d) {
    const RayHit h = data.nearestHit(o, d);
    if (!h.found()) return {};
    return {h.t, data.instances()[h.instance].instance, data.triangles()[h.triangle].firstIndex};
}

}  // namespace

TEST_CASE("a BVH holds every triangle once, and every box holds what lies below it", "[ray]") {
    const Soup soup = randomSoup(2000, 0.05f, 7);
    std::vector<Aabb> bounds(2000);
    for (size_t t = 0; t < bounds.size(); ++t)
        for (int k = 0; k < 3; ++k) bounds[t].grow(soup.positions[soup.indices[3 * t + size_t(k)]]);
    const Bvh bvh = buildBvh(bounds, 4);
    REQUIRE(bvh.order.size() == 2000);
    std::vector<int> seen(2000, 0);
    size_t leaves = 0;
    // Walk from the root: each node is reached once, and holds its children or primitives.
    std::vector<uint32_t> stack{0};
    std::vector<int> reached(bvh.nodes.size(), 0);
    while (!stack.empty()) {
        const uint32_t i = stack.back();
        stack.pop_back();
        ++reached[i];
        const BvhNode& n = bvh.nodes[i];
        if (n.count == 0) {
            REQUIRE(n.first + 1 < bvh.nodes.size());
            CHECK(contains(boxOf(n), boxOf(bvh.nodes[n.first])));
            CHECK(contains(boxOf(n), boxOf(bvh.nodes[n.first + 1])));
            stack.push_back(n.first), stack.push_back(n.first + 1);
            continue;
        }
        ++leaves;
        CHECK(n.count <= 4);
        for (uint32_t k = n.first; k < n.first + n.count; ++k) {
            ++seen[bvh.order[k]];
            CHECK(contains(boxOf(n), bounds[bvh.order[k]]));
        }
    }
    for (int s : seen) REQUIRE(s == 1);
    for (int r : reached) REQUIRE(r == 1);  // no node orphaned or shared
    INFO(leaves << " leaves, " << bvh.nodes.size() << " nodes");
    // SAH on small scattered triangles makes leaves of 1–4: at least 2000 / 4 of them.
    CHECK(leaves >= 500);
    CHECK(bvh.nodes.size() == 2 * leaves - 1);
}

TEST_CASE("a BVH over coincident triangles ends, its leaves bounded", "[ray]") {
    std::vector<Aabb> bounds(1000, Aabb{glm::vec3(0.0f), glm::vec3(1.0f)});
    bounds[17] = {};  // an empty box (a degenerate primitive) is left out
    const Bvh bvh = buildBvh(bounds, 4);
    CHECK(bvh.order.size() == 999);
    for (const BvhNode& n : bvh.nodes) CHECK(n.count <= 64);
    CHECK(buildBvh(std::vector<Aabb>{}).nodes.empty());
}

TEST_CASE("a BVH is never deeper than its depth limit (the shaders' traversal stack)", "[ray]") {
    // The shaders walk a hierarchy with a stack of kMaxBvhDepth entries, one pushed per
    // level, so a deeper tree would lose the subtrees past it. Scattered triangles whose
    // SAH tree is deeper than a limit of 8 are built within it: median splits where the
    // SAH's cuts would pass it, leaves no larger than the 2000 / 2^8 the limit forces,
    // every triangle still in one leaf. The limit must have acted: without it the tree is
    // deeper (and within the shaders' stack).
    const Soup soup = randomSoup(2000, 0.05f, 11);
    std::vector<Aabb> bounds(2000);
    for (size_t t = 0; t < bounds.size(); ++t)
        for (int k = 0; k < 3; ++k) bounds[t].grow(soup.positions[soup.indices[3 * t + size_t(k)]]);
    auto deepestLeaf = [&](const Bvh& bvh, uint32_t largestLeaf) {
        std::vector<int> seen(bounds.size(), 0);
        std::vector<std::pair<uint32_t, int>> stack{{0u, 0}};
        int deepest = 0;
        while (!stack.empty()) {
            const auto [i, depth] = stack.back();
            stack.pop_back();
            deepest = std::max(deepest, depth);
            const BvhNode& n = bvh.nodes[i];
            if (n.count == 0) {
                stack.push_back({n.first, depth + 1}), stack.push_back({n.first + 1, depth + 1});
                continue;
            }
            CHECK(n.count <= largestLeaf);
            for (uint32_t k = n.first; k < n.first + n.count; ++k) ++seen[bvh.order[k]];
        }
        for (int s : seen) REQUIRE(s == 1);
        return deepest;
    };
    const int free = deepestLeaf(buildBvh(bounds, 4), 4);
    const int limited = deepestLeaf(buildBvh(bounds, 4, 8), 8);
    INFO("deepest leaf: " << free << " by the SAH alone, " << limited << " limited to 8");
    CHECK(free > 8);
    CHECK(free <= int(kMaxBvhDepth));
    CHECK(limited <= 8);
}

TEST_CASE("rays through two levels find the nearest triangle that testing every one finds", "[ray]") {
    // Two meshes — scattered triangles, and a 20 × 20 grid of quads (many shared edges,
    // where a ray meets two triangles at once) — placed five times with rotations, uniform
    // scales and moves; 3 000 rays from around the scene toward it.
    const Soup scattered = randomSoup(400, 0.2f, 3);
    Soup grid;
    for (int y = 0; y <= 20; ++y)
        for (int x = 0; x <= 20; ++x) grid.positions.push_back({x / 10.0f - 1.0f, y / 10.0f - 1.0f, 0.1f * std::sin(x + y)});
    for (uint32_t y = 0; y < 20; ++y)
        for (uint32_t x = 0; x < 20; ++x) {
            const uint32_t a = y * 21 + x;
            for (uint32_t i : {a, a + 1, a + 22, a, a + 22, a + 21}) grid.indices.push_back(i);
        }
    const Soup* meshes[] = {&scattered, &grid};
    RayMeshData data;
    uint32_t firstIndex = 0;
    for (const Soup* m : meshes) {
        data.addMesh({m->positions, m->indices, firstIndex});
        firstIndex += uint32_t(m->indices.size());
    }
    const glm::mat4 I(1.0f);
    std::vector<RayInstanceSource> instances = {
        {0, I, 100, 0, true},
        {1, glm::rotate(glm::translate(I, {0, 0, -2}), 0.7f, glm::normalize(glm::vec3(1, 2, 0))), 101, 0, true},
        {0, glm::scale(glm::translate(I, {2.5f, 0, 0}), glm::vec3(0.5f)), 102, 0, true},
        {1, glm::rotate(glm::translate(I, {-2, 1, 0.5f}), 2.0f, glm::vec3(0, 1, 0)), 103, 0, true},
        {0, glm::scale(glm::rotate(glm::translate(I, {0, -2, 1}), 1.1f, glm::vec3(1, 0, 0)), glm::vec3(1.7f)), 104, 0, true},
    };
    data.setInstances(instances);
    REQUIRE(data.instances().size() == 5);
    REQUIRE(data.triangles().size() == 400 + 800);

    // Brute force in world space, from the sources.
    auto bruteForce = [&](glm::vec3 o, glm::vec3 d) {
        Found f;
        uint32_t meshFirst[2] = {0, uint32_t(scattered.indices.size())};
        for (const RayInstanceSource& inst : instances) {
            const Soup& m = *meshes[inst.mesh];
            for (size_t t = 0; t < m.indices.size() / 3; ++t) {
                glm::vec3 v[3];
                for (int k = 0; k < 3; ++k) v[k] = glm::vec3(inst.model * glm::vec4(m.positions[m.indices[3 * t + size_t(k)]], 1));
                const float h = hitTriangle(o, d, v[0], v[1] - v[0], v[2] - v[0], f.t);
                if (h > 0.0f) f = {h, inst.instance, meshFirst[inst.mesh] + uint32_t(3 * t)};
            }
        }
        return f;
    };
    std::mt19937 rng(11);
    std::uniform_real_distribution<float> u(-1.0f, 1.0f);
    int hits = 0, agree = 0;
    float worst = 0.0f;
    for (int r = 0; r < 3000; ++r) {
        const glm::vec3 o = 5.0f * glm::normalize(glm::vec3(u(rng), u(rng), u(rng)));
        const glm::vec3 d = glm::normalize(glm::vec3(u(rng), u(rng), u(rng)) * 2.0f - o);
        const Found a = traceHierarchy(data, o, d), b = bruteForce(o, d);
        REQUIRE(std::isinf(a.t) == std::isinf(b.t));
        if (std::isinf(a.t)) continue;
        ++hits;
        // The same t up to the rounding of a ray moved into a mesh's space (1e-4 of ~5 m).
        worst = std::max(worst, std::abs(a.t - b.t));
        if (a.instance == b.instance && a.firstIndex == b.firstIndex) ++agree;
    }
    INFO(hits << " hits, " << agree << " on the same triangle, worst |Δt| " << worst);
    CHECK(hits > 1000);
    CHECK(worst < 5e-4f);
    // Where two triangles meet the ray at one t (a shared edge) either may be named.
    CHECK(agree >= hits - 5);
}

TEST_CASE("an instance of a mesh without triangles is left out of the top level", "[ray]") {
    RayMeshData data;
    const std::vector<glm::vec3> none;
    data.addMesh({none, {}, 0});
    const std::vector<glm::vec3> tri = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
    const std::vector<uint32_t> idx = {0, 1, 2};
    data.addMesh({tri, idx, 0});
    const std::vector<RayInstanceSource> instances = {{0, glm::mat4(1.0f), 5, 0, false}, {1, glm::mat4(1.0f), 6, 0, false}};
    data.setInstances(instances);
    REQUIRE(data.instances().size() == 1);
    CHECK(data.instances()[0].instance == 6);
    const Found f = traceHierarchy(data, {0.2f, 0.2f, 1.0f}, {0, 0, -1});
    CHECK(f.t == Approx(1.0f));
    // One-sided: from behind the winding the triangle is not there; two-sided it is.
    CHECK(std::isinf(traceHierarchy(data, {0.2f, 0.2f, -1.0f}, {0, 0, 1}).t));
    const std::vector<RayInstanceSource> twoSided = {{1, glm::mat4(1.0f), 6, 0, true}};
    data.setInstances(twoSided);
    CHECK(traceHierarchy(data, {0.2f, 0.2f, -1.0f}, {0, 0, 1}).t == Approx(1.0f));
    CHECK(data.nearestHit({0.2f, 0.2f, -1.0f}, {0, 0, 1}, 0.5f).found() == false);  // beyond tMax
}
