// kiln/scene_view.hpp — what a pass sees of the scene: camera, light, instances to
// draw, and a version per category so the host can skip passes whose inputs did not
// change. Built by the host once per frame from the simulation; read-only for passes.
#pragma once

#include <cstdint>

#include <glm/glm.hpp>

#include "kiln/declare.hpp"

namespace kiln {

// What drawScene() can draw; a filter is a mask of these.
enum DrawCategory : uint32_t {
    kDrawBox = 1u << 0,        // the five walls (the floor carries the wood grain)
    kDrawLamp = 1u << 1,       // the emissive hemisphere under the ceiling
    kDrawTumblers = 1u << 2,
    kDrawMarbles = 1u << 3,
    kDrawFireballs = 1u << 4,
    kDrawParticles = 1u << 5,
    kDrawShadowCasters = kDrawTumblers | kDrawMarbles,  // fireballs emit, they don't cast
    kDrawAll = 0x3f,
};

enum class Lod : uint8_t { High, Low };

struct DrawFilter {
    uint32_t categories = kDrawAll;
    Lod lod = Lod::High;
};

// Per-instance data as the shaders see it (std430, binding kInstanceBinding); keep in
// sync with shaders/common/scene.glsl.
struct alignas(16) GpuInstance {
    glm::mat4 model;
    glm::vec4 albedo;    // rgb, a = material (0 plain, 1 wood grain)
    glm::vec4 emissive;  // rgb radiance (already × strength), a = highlight (picked) 0/1
};

// The per-frame uniform block (std140, binding kFrameBinding); keep in sync with
// shaders/common/frame.glsl.
struct GpuFrame {
    glm::mat4 view, proj, viewProj, invViewProj;
    glm::vec4 cameraPos;     // xyz, w unused
    glm::vec4 lightPos;      // xyz = lamp centre (outside the box), w = lamp radius
    glm::vec4 lightColor;    // rgb × intensity, w = intensity
    glm::vec4 outputSize;    // w, h, 1/w, 1/h
    glm::vec4 time;          // seconds, dt, frame index, unused
};

inline constexpr unsigned kFrameBinding = 0;      // uniform block
inline constexpr unsigned kInstanceBinding = 0;   // shader storage block

int sceneCategoryIndex(SceneCategory);
int drawCategoryIndex(DrawCategory);

struct SceneView {
    GpuFrame frame{};
    glm::vec3 cameraPos{0.0f};
    glm::vec3 lightPos{0.0f, 1.1f, 0.0f};
    float lampRadius = 0.35f;
    glm::vec3 lightColor{1.0f};

    // Versions of each SceneCategory (declare.hpp): bumped by the host when that part
    // changed. Index with sceneCategoryIndex().
    uint64_t versions[6] = {};
    uint32_t counts[6] = {};  // instances per DrawCategory bit index
    // Bumped when that DrawCategory's instances changed (finer than kSceneBodies: the
    // shadow map cares whether a caster moved, not whether a fireball did).
    uint64_t drawVersions[6] = {};

    uint64_t version(SceneCategory c) const;
    uint32_t count(DrawCategory c) const;
    uint64_t drawVersion(DrawCategory c) const { return drawVersions[drawCategoryIndex(c)]; }
};


inline uint64_t SceneView::version(SceneCategory c) const { return versions[sceneCategoryIndex(c)]; }
inline uint32_t SceneView::count(DrawCategory c) const { return counts[drawCategoryIndex(c)]; }

inline int sceneCategoryIndex(SceneCategory c) {
    for (int i = 0; i < 6; ++i)
        if (c == (1u << i)) return i;
    return 0;
}
inline int drawCategoryIndex(DrawCategory c) {
    for (int i = 0; i < 6; ++i)
        if (c == (1u << i)) return i;
    return 0;
}

}  // namespace kiln
