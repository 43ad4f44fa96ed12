#include "scene/mesh.hpp"

#include <algorithm>
#include <cmath>
#include <map>

namespace kiln::scene {

namespace {
constexpr float kPi = 3.14159265358979f;
}

MeshData makeQuad() {
    MeshData m;
    const glm::vec3 n(0, 1, 0);
    m.vertices = {{{-1, 0, -1}, n}, {{1, 0, -1}, n}, {{1, 0, 1}, n}, {{-1, 0, 1}, n}};
    m.indices = {0, 2, 1, 0, 3, 2};  // counter-clockwise seen from +y
    return m;
}

MeshData makeLampDome(glm::vec3 centre, float radius, int level, float clipY) {
    const float p = (1.0f + std::sqrt(5.0f)) / 2.0f;
    std::vector<glm::vec3> v = {{-1, p, 0}, {1, p, 0}, {-1, -p, 0}, {1, -p, 0}, {0, -1, p}, {0, 1, p},
                                {0, -1, -p}, {0, 1, -p}, {p, 0, -1}, {p, 0, 1}, {-p, 0, -1}, {-p, 0, 1}};
    for (auto& x : v) x = glm::normalize(x);
    std::vector<glm::uvec3> f = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
                                 {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
                                 {3, 8, 9},  {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
    for (int l = 0; l < level; ++l) {
        std::map<std::pair<uint32_t, uint32_t>, uint32_t> mid;
        auto midpoint = [&](uint32_t a, uint32_t b) {
            auto key = std::minmax(a, b);
            auto it = mid.find(key);
            if (it != mid.end()) return it->second;
            v.push_back(glm::normalize(v[a] + v[b]));
            return mid[key] = static_cast<uint32_t>(v.size() - 1);
        };
        std::vector<glm::uvec3> next;
        for (auto& t : f) {
            uint32_t a = midpoint(t.x, t.y), b = midpoint(t.y, t.z), c = midpoint(t.z, t.x);
            next.insert(next.end(), {{t.x, a, c}, {t.y, b, a}, {t.z, c, b}, {a, b, c}});
        }
        f = std::move(next);
    }
    MeshData m;
    for (auto& x : v) m.vertices.push_back({centre + radius * x, x});
    for (auto& t : f) {
        bool inside = false;
        for (int k = 0; k < 3; ++k) inside |= m.vertices[t[k]].position.y < clipY;
        if (inside) m.indices.insert(m.indices.end(), {t.x, t.y, t.z});
    }
    return m;
}

MeshData makeUvSphere(int slices, int stacks) {
    MeshData m;
    for (int i = 0; i <= stacks; ++i) {
        float phi = kPi * static_cast<float>(i) / static_cast<float>(stacks);
        for (int j = 0; j <= slices; ++j) {
            float th = 2.0f * kPi * static_cast<float>(j) / static_cast<float>(slices);
            glm::vec3 n(std::sin(phi) * std::cos(th), std::cos(phi), std::sin(phi) * std::sin(th));
            m.vertices.push_back({n, n});
        }
    }
    for (int i = 0; i < stacks; ++i)
        for (int j = 0; j < slices; ++j) {
            uint32_t a = static_cast<uint32_t>(i * (slices + 1) + j), b = a + static_cast<uint32_t>(slices + 1);
            m.indices.insert(m.indices.end(), {a, a + 1, b, a + 1, b + 1, b});
        }
    return m;
}

MeshData makeParticle() {
    MeshData m;
    const glm::vec3 axes[6] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
    for (const glm::vec3& a : axes) m.vertices.push_back({a * 1.35f, a});
    // One face per octant, wound counter-clockwise seen from outside.
    for (uint32_t x : {0u, 1u})
        for (uint32_t y : {2u, 3u})
            for (uint32_t z : {4u, 5u}) {
                const bool flip = ((x == 1) != (y == 3)) != (z == 5);  // an odd number of negative axes
                if (flip) m.indices.insert(m.indices.end(), {x, z, y});
                else m.indices.insert(m.indices.end(), {x, y, z});
            }
    return m;
}

float areaPreservingInflation(float r, int n) {
    const double ratio = n * std::sin(2.0 * M_PI / n) / (2.0 * M_PI);
    return float(r * (1.0 / std::sqrt(ratio) - 1.0));
}

MeshData makeTumbler(float b, float t, float alpha, int slices, int stacks, float inflate) {
    // Profile rings from the bottom pole to the top pole: lower cap from −90° up to
    // latitude α (where the cone touches), the cone band, then the upper cap from α
    // to +90°. Cap normals are radial; the band's normal is the side normal.
    const float yt = (b - t) / std::sin(alpha);
    struct Ring { float y, r; glm::vec2 n; };  // n = (radial, vertical) normal
    std::vector<Ring> rings;
    for (int i = 0; i <= stacks; ++i) {
        float lat = -kPi / 2 + (alpha + kPi / 2) * static_cast<float>(i) / static_cast<float>(stacks);
        rings.push_back({b * std::sin(lat), b * std::cos(lat), {std::cos(lat), std::sin(lat)}});
    }
    for (int i = 0; i <= stacks; ++i) {
        float lat = alpha + (kPi / 2 - alpha) * static_cast<float>(i) / static_cast<float>(stacks);
        rings.push_back({yt + t * std::sin(lat), t * std::cos(lat), {std::cos(lat), std::sin(lat)}});
    }
    for (auto& ring : rings) ring.y += inflate * ring.n.y, ring.r += inflate * ring.n.x;
    MeshData m;
    for (auto& ring : rings)
        for (int j = 0; j <= slices; ++j) {
            float th = 2.0f * kPi * static_cast<float>(j) / static_cast<float>(slices);
            glm::vec3 dir(std::cos(th), 0, std::sin(th));
            m.vertices.push_back({glm::vec3(dir.x * ring.r, ring.y, dir.z * ring.r),
                                  glm::normalize(glm::vec3(dir.x * ring.n.x, ring.n.y, dir.z * ring.n.x))});
        }
    // Consecutive rings are joined; the lower cap's last ring and the upper cap's
    // first ring are the cone's two ends, so that quad strip is the cone band.
    for (size_t i = 0; i + 1 < rings.size(); ++i)
        for (int j = 0; j < slices; ++j) {
            uint32_t a = static_cast<uint32_t>(i * (slices + 1) + j), c = a + static_cast<uint32_t>(slices + 1);
            m.indices.insert(m.indices.end(), {a, c, a + 1, a + 1, c, c + 1});
        }
    return m;
}

}  // namespace kiln::scene
