// app/scene.hpp — turns scene content (the box, the lamp, bodies, particles) into
// GPU instances and draws them by category for the passes (drawScene).
//
// All meshes live in one vertex and one index buffer behind one VAO; instances live
// in one shader storage buffer, grouped (mesh, category) so a filter is a handful of
// instanced draws. Uploads happen only for categories whose version changed.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "app/mesh.hpp"
#include "kiln/gl.hpp"
#include "kiln/scene_view.hpp"

namespace kiln::app {

struct BoxLook {
    glm::vec3 left{0.95f, 0.45f, 0.1f};    // orange
    glm::vec3 right{0.35f, 0.65f, 0.95f};  // sky blue
    glm::vec3 other{0.85f, 0.82f, 0.78f};  // back wall, ceiling, floor
    glm::vec3 lampCentre{0.0f, 1.1f, 0.0f};
    float lampRadius = 0.35f;
    glm::vec3 lampColor{1.0f, 0.95f, 0.85f};
    float lampIntensity = 4.0f;
};

struct BodyInstance {
    DrawCategory category = kDrawTumblers;  // tumblers, marbles, fireballs
    glm::mat4 model{1.0f};                  // for spheres: translate × scale(radius)
    glm::vec3 albedo{1.0f};
    glm::vec3 emissive{0.0f};
    bool highlighted = false;
};

struct ParticleInstance {
    glm::vec3 position;
    float radius;
    glm::vec3 emissive;
};

struct TumblerShapeParams {
    float b = 0.2f, t = 0.1f, alpha = 0.349066f;
};

class SceneRenderer {
public:
    void init(const BoxLook&, const TumblerShapeParams&);
    void setBox(const BoxLook&);
    void setBodies(const std::vector<BodyInstance>&);
    void setParticles(const std::vector<ParticleInstance>&);
    // Uploads what changed; call once per frame before the passes run.
    void upload();
    // Instanced draws of every group matching the filter with the current program.
    void draw(const DrawFilter&) const;
    uint32_t count(DrawCategory c) const;
    // Bumped whenever a category's instance data changed (content hash).
    uint64_t version(DrawCategory c) const { return versions_[drawCategoryIndex(c)]; }
    const BoxLook& box() const { return box_; }

private:
    enum MeshId { kQuad, kLamp, kTumblerHigh, kTumblerLow, kSphereHigh, kSphereLow, kMeshCount };
    struct MeshRange { uint32_t firstIndex = 0, indexCount = 0, baseVertex = 0; };
    struct Group { MeshId mesh; DrawCategory category; Lod lod; bool anyLod; uint32_t first, count; };

    void rebuildInstances();

    BoxLook box_;
    std::array<MeshRange, kMeshCount> meshes_{};
    gl::Buffer vertexBuffer_, indexBuffer_;
    gl::VertexArrayHandle vao_;
    gl::Buffer instanceBuffer_, instanceIds_;
    size_t instanceCapacity_ = 0;
    std::vector<GpuInstance> staticInstances_, bodyInstances_, particleInstances_;
    std::vector<BodyInstance> bodies_;
    std::vector<Group> groups_;
    bool dirty_ = true;
    uint64_t versions_[6] = {};
    uint64_t hashes_[6] = {};
    void noteContents(DrawCategory, const GpuInstance* begin, size_t count);
};

}  // namespace kiln::app
