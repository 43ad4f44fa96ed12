#include "scene/redraw_region.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace kiln::scene {

namespace {

// The picture's bounds (in normalized device coordinates) of the points added.
struct ScreenBounds {
    const glm::mat4& viewProj;
    glm::vec2 lo{std::numeric_limits<float>::max()}, hi{std::numeric_limits<float>::lowest()};
    bool behindCamera = false;

    void add(glm::vec3 p) {
        const glm::vec4 clip = viewProj * glm::vec4(p, 1.0f);
        if (clip.w <= 1e-4f) {
            behindCamera = true;
            return;
        }
        const glm::vec2 ndc = glm::vec2(clip) / clip.w;
        lo = glm::min(lo, ndc), hi = glm::max(hi, ndc);
    }
    // The corners of the cube round a ball: its projection covers the ball's.
    void addBall(glm::vec3 centre, float radius) {
        for (int corner = 0; corner < 8; ++corner)
            add(centre + radius * glm::vec3(corner & 1 ? 1 : -1, corner & 2 ? 1 : -1, corner & 4 ? 1 : -1));
    }
};

// Where the ray o + t·d (t ≥ 0) leaves the box, if it meets it.
std::optional<float> exitFromBox(glm::vec3 o, glm::vec3 d, glm::vec3 lo, glm::vec3 hi) {
    float tNear = 0.0f, tFar = std::numeric_limits<float>::max();
    for (int a = 0; a < 3; ++a) {
        if (std::abs(d[a]) < 1e-9f) {
            if (o[a] < lo[a] || o[a] > hi[a]) return std::nullopt;
            continue;
        }
        float t0 = (lo[a] - o[a]) / d[a], t1 = (hi[a] - o[a]) / d[a];
        if (t0 > t1) std::swap(t0, t1);
        tNear = std::max(tNear, t0), tFar = std::min(tFar, t1);
    }
    if (tFar < tNear) return std::nullopt;
    return tFar;
}

// The shadow of the ball (c, r) in the lamp's light, clipped to the room, as points
// whose convex hull holds it. False when the ball reaches into the lamp's ball (its
// shadow is not a cone).
bool addShadow(ScreenBounds& bounds, glm::vec3 c, float r, const RedrawView& view) {
    const glm::vec3 lamp = view.lampCentre;
    const float lampR = view.lampRadius;
    if (glm::distance(c, lamp) <= lampR + r) return false;
    // The apex of the cone tangent to both balls, between them; beyond the body the
    // cone holds every line through both (a positive combination of two directions
    // inside it), and nothing of it lies nearer the apex than the body's near side.
    const glm::vec3 apex = (lampR * c + r * lamp) / (lampR + r);
    const glm::vec3 axis = glm::normalize(c - apex);
    const float toCentre = glm::distance(c, apex);
    const float sinHalf = r / toCentre;
    const float tanHalf = sinHalf / std::sqrt(1.0f - sinHalf * sinHalf);
    // Its generators are sampled as the edges of a pyramid round the cone (each face
    // tangent to it, 2 % spare), and the room's edges tested against the cone round
    // that pyramid: the hull of what is added holds the pyramid clipped to the room.
    constexpr int kGenerators = 32;
    const float kSpread = 1.0f / std::cos(float(M_PI) / kGenerators);
    const float tanPyramid = tanHalf * kSpread * 1.02f;
    const float cosOuter = 1.0f / std::sqrt(1.0f + std::pow(tanPyramid * kSpread, 2.0f));
    // The pyramid's section nearest the apex (at the body's near side) lies within
    // 1.5 r of its centre.
    bounds.addBall(c, 1.5f * r);
    const glm::vec3 u = glm::normalize(glm::cross(axis, std::abs(axis.y) < 0.9f ? glm::vec3(0, 1, 0) : glm::vec3(1, 0, 0)));
    const glm::vec3 v = glm::cross(axis, u);
    for (int k = 0; k < kGenerators; ++k) {
        const float phi = 2.0f * float(M_PI) * float(k) / kGenerators;
        const glm::vec3 g = glm::normalize(axis + tanPyramid * (std::cos(phi) * u + std::sin(phi) * v));
        if (auto t = exitFromBox(apex, g, view.roomMin, view.roomMax)) bounds.add(apex + *t * g);
    }
    // Where the room's edges cross the cone (the hull's corners in the room's corners):
    // samples inside it and each one's neighbours, so a crossing between two samples
    // lies on a segment of the hull.
    constexpr int kSamples = 32;
    const glm::vec3 lo = view.roomMin, hi = view.roomMax;
    for (int a = 0; a < 3; ++a)
        for (int corner = 0; corner < 4; ++corner) {
            const int b = (a + 1) % 3, d = (a + 2) % 3;
            glm::vec3 p0;
            p0[a] = lo[a], p0[b] = corner & 1 ? hi[b] : lo[b], p0[d] = corner & 2 ? hi[d] : lo[d];
            glm::vec3 p1 = p0;
            p1[a] = hi[a];
            auto sample = [&](int i) { return glm::mix(p0, p1, float(i) / kSamples); };
            auto inside = [&](int i) {
                if (i < 0 || i > kSamples) return false;
                const glm::vec3 w = sample(i) - apex;
                const float len = glm::length(w);
                return len > 0.0f && glm::dot(w, axis) >= cosOuter * len;
            };
            for (int i = 0; i <= kSamples; ++i)
                if (inside(i - 1) || inside(i) || inside(i + 1)) bounds.add(sample(i));
        }
    return true;
}

}  // namespace

std::optional<PixelRect> changedPixels(const std::vector<glm::vec4>& spheres, const RedrawView& view,
                                       const RedrawReach& reach) {
    ScreenBounds bounds{view.viewProj};
    for (const glm::vec4& s : spheres) {
        bounds.addBall(glm::vec3(s), s.w + reach.metres);
        if (!addShadow(bounds, glm::vec3(s), s.w, view)) return std::nullopt;
    }
    if (bounds.behindCamera) return std::nullopt;
    if (spheres.empty() || bounds.lo.x > bounds.hi.x) return PixelRect{};
    const glm::vec2 size(float(view.width), float(view.height));
    const glm::vec2 lo = glm::floor((bounds.lo * 0.5f + 0.5f) * size) - float(reach.pixels);
    const glm::vec2 hi = glm::ceil((bounds.hi * 0.5f + 0.5f) * size) + float(reach.pixels);
    const int x0 = int(std::clamp(lo.x, 0.0f, size.x)), x1 = int(std::clamp(hi.x, 0.0f, size.x));
    const int y0 = int(std::clamp(lo.y, 0.0f, size.y)), y1 = int(std::clamp(hi.y, 0.0f, size.y));
    if (x1 <= x0 || y1 <= y0) return PixelRect{};
    return PixelRect{x0, y0, x1 - x0, y1 - y0};
}

PixelRect redrawBand(int index, int width, int height) {
    const int band = ((index % kRedrawBands) + kRedrawBands) % kRedrawBands;
    const int y0 = int(int64_t(height) * band / kRedrawBands), y1 = int(int64_t(height) * (band + 1) / kRedrawBands);
    return PixelRect{0, y0, width, y1 - y0};
}

}  // namespace kiln::scene
