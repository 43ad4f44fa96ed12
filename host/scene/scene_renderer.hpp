// scene/scene_renderer.hpp — the scene's geometry on the GPU, drawn by category for
// the passes (drawScene).
//
// All meshes live in one vertex and one index buffer behind one VAO; instances live in
// one shader storage buffer, grouped (mesh, category) so a filter is a handful of
// instanced draws. Each geometry category carries a content version: it changes only
// when that category's instances changed, so a pass that reads the shadow casters does
// not re-run because a fireball moved.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "kiln/gl.hpp"
#include "kiln/scene_view.hpp"
#include "model/model.hpp"
#include "scene/mesh.hpp"
#include "ray/ray_meshes.hpp"
#include "run/pass_context.hpp"

namespace kiln::scene {

// How the scene file says the scene looks (sim::Scene's box, lamp, tumbler shape).
struct SceneLook {
    glm::vec3 left{0.95f, 0.45f, 0.1f};    // orange
    glm::vec3 right{0.35f, 0.65f, 0.95f};  // sky blue
    glm::vec3 other{0.85f, 0.82f, 0.78f};  // back wall, ceiling (the floor is wood)
    glm::vec3 ringsLight{0.72f, 0.52f, 0.32f}, ringsDark{0.45f, 0.28f, 0.15f};
    float woodRingFrequency = 14.0f;
    glm::vec3 wallEmission{0.0f};  // radiance every wall emits
    bool closed = false;           // a front wall at z = +1 (colour `other`)
    bool walls = true;             // false: no walls (a model alone)
    bool lamp = true;              // the lamp dome (clipped at y = 1, where the ceiling is)
    glm::vec3 lampCentre{0.0f, 1.1f, 0.0f};
    float lampRadius = 0.35f;
    glm::vec3 lampColor{1.0f, 0.95f, 0.85f};
    float lampIntensity = 4.0f;
    float tumblerB = 0.2f, tumblerT = 0.1f, tumblerAlpha = 0.349066f;
};

struct BodyInstance {
    SceneCategory category = kSceneRoundCones;  // tumblers, marbles, fireballs
    glm::mat4 model{1.0f};                    // for spheres: translate × scale(radius)
    glm::vec3 albedo{1.0f};
    glm::vec3 emissive{0.0f};
    bool highlighted = false;
};

// A model (glTF) placed in the scene: its instances' transforms are applied after
// `placement`.
struct PlacedModel {
    std::shared_ptr<const model::Model> model;
    glm::mat4 placement{1.0f};
};

// The most texels a side of the placed meshes' texture layers (every layer of an array
// has one size: larger images are scaled down to it).
inline constexpr int kMaterialLayerSide = 1024;

struct ParticleInstance {
    glm::vec3 position;
    float radius;
    glm::vec3 emissive;
};

// The sphere mesh for a marble or fireball whose radius spans `radiusPx` pixels on
// screen: 0 = 32 segments around, 1 = 16, 2 = 10 (the voxelization mesh). A polygon of
// n segments strays from its circle by r·(1 − cos(π/n)); the thresholds keep that under
// a pixel up to a 200-px radius (tests/integration/test_scene.cpp).
constexpr float kSphereNearPx = 48.0f, kSphereFarPx = 12.0f;
inline int sphereLevelFor(float radiusPx) { return radiusPx >= kSphereNearPx ? 0 : radiusPx >= kSphereFarPx ? 1 : 2; }
inline constexpr int kSphereSegments[3] = {32, 16, 10};

// The tumbler meshes, slices around × stacks a cap: the camera's near one, and its far
// one while every tumbler's bounding ball spans under kTumblerNearPx pixels of radius on
// screen (each strays from the round cone by under a pixel where it is drawn:
// tests/integration/test_scene.cpp); the shadow map's, inflated to the round one's
// cross-section (a shadow as large); voxelize's. The shipped tumblers' balls span 122 px
// at 720², 183 at 1080p, 365 at 4K: the far mesh at the first two, half the near one's
// triangles (the G-buffer 6.5 → 5.4 ms at 720² on llvmpipe, relMSE unchanged: 0.01064
// against 0.01062 at 128², t = 0.5; 0.01185 against 0.01186 at 256², t = 0. The shadow
// map's 24 × 8, uninflated, saved 1.0 ms but cost 256²'s relMSE 0.0002). Voxelize's
// 8 × 3 lies inside the round cone by under the half voxel (at 32³) that conservative
// rasterization grows it by (tests/integration/test_scene.cpp): every triangle costs
// llvmpipe's geometry shader and a few 4 × 4 blocks of lit fragments, and 12 × 4 took
// voxelize 0.8 ms more at 720² for relMSE 0.01156 against 0.01159 at 256², t = 0.
struct TumblerMesh {
    int slices, stacks;
    bool inflated;
};
inline constexpr TumblerMesh kTumblerNear{48, 16, false}, kTumblerFar{32, 12, false}, kTumblerShadow{24, 8, true},
    kTumblerVoxels{8, 3, false};
constexpr float kTumblerNearPx = 250.0f;
// The ball about the tumbler's origin (its lower ball's centre) that holds its mesh.
inline float tumblerBoundingRadius(float b, float t, float alpha) {
    return std::max(b, (b - t) / std::sin(alpha) + t) * 1.05f;
}

class SceneRenderer final : public run::SceneDraw {
public:
    // The walls' instances, and every mesh rebuilt at the next upload() (the lamp dome
    // and the tumblers follow the look). Called on every scene (re)load.
    void setLook(const SceneLook&);
    void setBodies(const std::vector<BodyInstance>&);
    void setParticles(const std::vector<ParticleInstance>&);
    // The models the scene file places (kSceneMeshes): their meshes, instances and
    // textures. Returns false with a one-line error (GPU memory) and keeps the last ones.
    bool setModels(const std::vector<PlacedModel>&, std::string& error);
    // The placed meshes' ray-tracing buffers (SceneView::rayMeshes), as last uploaded.
    kiln::RayMeshes rayMeshes() const;
    // The same on the CPU (tests and the CPU tracers read it).
    const ray::RayMeshData& rayMeshData() const { return rayData_; }
    // The name of the material a placed mesh's instance shows (the index is the scene's,
    // as RayInstance::instance holds it): its glTF name, "material N" when it has none,
    // "(no material)" for glTF's default; empty for an instance that is not a placed mesh.
    std::string materialNameOf(uint32_t sceneInstance) const;
    // The texture arrays of SceneView::materialTextures (0 where there are none).
    GLuint materialTexture(int which) const { return which == 0 ? colorLayers_.id() : dataLayers_.id(); }
    // The camera, for the spheres' level of detail and the particles' order: its
    // position, the unit vector it looks along, and the pixels a unit length spans at
    // unit distance (projection[1][1] × height / 2).
    void setViewer(glm::vec3 eye, glm::vec3 forward, float pixelsPerUnit);
    // Uploads what changed; call once per frame before the passes run.
    void upload();
    // Instanced draws of every group matching the filter with the current program.
    void draw(const DrawFilter&) const override;
    // The triangles draw() would issue for the filter (as uploaded).
    uint64_t triangles(const DrawFilter&) const;
    void bindInstances() const override;
    // Instances of one geometry category (kScenePlanes ... kSceneParticles).
    uint32_t count(SceneCategory single) const { return counts_[sceneCategoryIndex(single)]; }
    // Changes whenever that geometry category's instance contents changed.
    uint64_t version(SceneCategory single) const { return versions_[sceneCategoryIndex(single)]; }
    // The bodies (tumblers, marbles, fireballs) that changed since the last call, as
    // spheres round where each was and where it is (xyz centre, w radius); nullopt when
    // the change cannot be put so (bodies added or removed, a new look).
    std::optional<std::vector<glm::vec4>> takeMovedBodies();

private:
    // The generated meshes; the placed models' follow them in meshes_.
    enum MeshId : uint32_t {
        kQuad, kLamp, kTumblerNearMesh, kTumblerFarMesh, kTumblerShadowMesh, kTumblerVoxelMesh,
        kSphereHigh, kSphereMid, kSphereLow, kParticle, kMeshCount
    };
    struct MeshRange { uint32_t firstIndex = 0, indexCount = 0, baseVertex = 0; };
    struct Group {
        uint32_t mesh;
        SceneCategory category;
        Lod lod;
        bool anyLod;
        uint32_t first, count;
        bool twoSided = false;  // kSceneMeshes: the material's doubleSided
    };
    // Calls visit(group) for each group draw() issues for the filter.
    template <class Visit>
    void forEachGroupDrawn(const DrawFilter&, Visit visit) const;

    void buildMeshes();
    // The placed models' images as layers of the two texture arrays; false (nothing
    // changed) when they would not fit the GPU memory they are given.
    bool buildMaterials(const std::vector<PlacedModel>&, std::string& error);
    // A placed mesh's instance: its transform and its material's factors and layers.
    GpuInstance materialInstance(const model::Model&, uint32_t materialBase, int material, const glm::mat4& world) const;

    struct SurfaceVertex {  // the second vertex stream (attributes 3 and 4)
        glm::vec2 uv{0.0f};
        glm::vec4 tangent{1.0f, 0.0f, 0.0f, 1.0f};
    };
    struct MaterialLayers {  // one per material of the placed models, in their order
        float base = -1.0f, emissive = -1.0f, normal = -1.0f;
        glm::vec3 meanBase{1.0f}, meanEmissive{1.0f};  // the textures' mean (linear), for coarse passes
    };
    std::vector<MaterialLayers> materialLayers_;
    void rebuildGroups();
    // The placed meshes' hierarchies (from the vertices and indices buildMeshes made).
    void buildRayMeshes(const std::vector<Vertex>& vertices, const std::vector<uint32_t>& indices);
    // Orders each sphere category's instances near → mid → far by their size on
    // screen and keeps the three counts in sphereLevels_; whether any tumbler is near.
    void chooseLevels();
    void noteContents(SceneCategory, const GpuInstance* begin, size_t count);
    void noteMovedBodies();

    std::vector<MeshRange> meshes_;
    SceneLook look_;
    std::vector<PlacedModel> models_;
    // The instances of kSceneMeshes, grouped by mesh (meshGroups_ in order).
    std::vector<GpuInstance> meshInstances_;
    std::vector<std::string> meshInstanceMaterials_;  // each one's material name
    struct MeshGroup { uint32_t mesh, instances; bool twoSided; };
    std::vector<MeshGroup> meshGroups_;
    gl::Buffer vertexBuffer_, surfaceBuffer_, indexBuffer_;
    ray::RayMeshData rayData_;
    gl::Buffer rayNodes_, rayTriangles_, rayInstances_, rayEmitters_;
    gl::TextureHandle colorLayers_, dataLayers_;
    gl::VertexArrayHandle vao_;
    gl::Buffer instanceBuffer_, instanceIds_;
    size_t instanceCapacity_ = 0;
    std::vector<GpuInstance> staticInstances_, bodyInstances_, particleInstances_;
    std::vector<Group> groups_;
    glm::vec3 eye_{0.0f}, forward_{0.0f, 0.0f, -1.0f};
    float pixelsPerUnit_ = 0.0f;
    std::vector<uint64_t> particleOrder_, sortScratch_;  // upload()'s: the particles' depths over their indices
    std::array<std::array<uint32_t, 3>, 2> sphereLevels_{};  // marbles, fireballs: near, mid, far
    bool tumblersNear_ = true;  // the camera's tumblers at their near mesh
    bool dirty_ = true;
    bool meshesStale_ = true;  // buildMeshes() is owed (upload() runs it)
    std::vector<GpuInstance> givenBodies_;  // the bodies as setBodies last got them
    std::vector<glm::vec4> movedBodies_;
    bool movedUnbounded_ = true;
    float tumblerRadius_ = 1.0f;  // the tumbler mesh's bounding ball about its origin
    uint32_t counts_[kSceneGeometryCount] = {};
    uint64_t versions_[kSceneGeometryCount] = {};
    uint64_t hashes_[kSceneGeometryCount] = {};
};

}  // namespace kiln::scene
