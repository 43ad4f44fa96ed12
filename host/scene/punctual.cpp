#include "scene/punctual.hpp"

#include <algorithm>
#include <cmath>

#include <glm/gtc/matrix_transform.hpp>

namespace kiln::scene {

namespace {
// An up vector not parallel to `forward`.
glm::vec3 upFor(glm::vec3 forward) { return std::abs(forward.y) < 0.99f ? glm::vec3(0, 1, 0) : glm::vec3(1, 0, 0); }
}  // namespace

bool shadowViewProj(const model::Light& light, glm::vec3 sceneMin, glm::vec3 sceneMax, glm::mat4& out) {
    const glm::vec3 centre = 0.5f * (sceneMin + sceneMax);
    const float radius = std::max(0.5f * glm::length(sceneMax - sceneMin), 1e-3f);
    const glm::vec3 d = glm::normalize(light.direction);
    switch (light.type) {
        case model::Light::Type::Directional: {
            const glm::vec3 eye = centre - d * (2.0f * radius);
            const glm::mat4 view = glm::lookAt(eye, centre, upFor(d));
            out = glm::ortho(-radius, radius, -radius, radius, 0.5f * radius, 3.5f * radius) * view;
            return true;
        }
        case model::Light::Type::Spot: {
            // To the farthest corner of the bounds (or the range): every caster it lights.
            float far = 0.0f;
            for (int c = 0; c < 8; ++c) {
                const glm::vec3 corner((c & 1) ? sceneMax.x : sceneMin.x, (c & 2) ? sceneMax.y : sceneMin.y,
                                       (c & 4) ? sceneMax.z : sceneMin.z);
                far = std::max(far, glm::length(corner - light.position));
            }
            if (light.range > 0.0f) far = std::min(far, light.range);
            far = std::max(far, 1e-2f);
            const float near = std::max(far * 1e-3f, 1e-3f);
            // The cone plus a texel's margin each side (the filter reads neighbours).
            const float fov = std::min(2.0f * light.outerCone * 1.05f, 3.0f);
            out = glm::perspective(fov, 1.0f, near, far) * glm::lookAt(light.position, light.position + d, upFor(d));
            return true;
        }
        case model::Light::Type::Point: return false;
    }
    return false;
}

void packPunctualLights(const std::vector<model::Light>& lights, glm::vec3 sceneMin, glm::vec3 sceneMax,
                        GpuFrame& frame) {
    const size_t n = std::min(lights.size(), size_t(kMaxPunctualLights));
    frame.punctualCount = glm::uvec4(uint32_t(n), 0u, 0u, 0u);
    int tiles = 0;
    for (size_t i = 0; i < n; ++i) {
        const model::Light& l = lights[i];
        GpuPunctualLight& g = frame.punctual[i];
        const float type = l.type == model::Light::Type::Directional ? 0.0f : l.type == model::Light::Type::Point ? 1.0f : 2.0f;
        g.position = glm::vec4(l.position, type);
        g.direction = glm::vec4(glm::normalize(l.direction), l.range);
        const float cosOuter = std::cos(l.outerCone), cosInner = std::cos(l.innerCone);
        g.cone = glm::vec4(cosOuter, 1.0f / std::max(cosInner - cosOuter, 1e-4f), 0.0f, 0.0f);
        glm::mat4 m(1.0f);
        const bool shadowed = tiles < kMaxShadowedLights && shadowViewProj(l, sceneMin, sceneMax, m);
        g.color = glm::vec4(l.color * l.intensity, shadowed ? float(tiles++) : -1.0f);
        g.shadowViewProj = m;
    }
}

}  // namespace kiln::scene
