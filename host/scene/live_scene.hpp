// scene/live_scene.hpp — the scene as Kiln runs it: the simulation (libkiln_sim's
// sim::World) loaded from a scene file, plus how that file says it looks. It steps the
// world and hands what changed to the scene renderer; data flows one way, from here to
// the renderer, and the app builds the SceneView from both (host/app/app.cpp).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "kiln/sim/world.hpp"
#include "scene/scene_renderer.hpp"

namespace kiln::scene {

class LiveScene {
public:
    // Loads `sceneFile` (with `seed` instead of the file's physics.seed when given): a
    // scene file (JSON), or a glTF file (.gltf, .glb) shown alone in the box, fitted to
    // it. On failure keeps the current world and returns false with a one-line error.
    bool load(const std::string& sceneFile, std::optional<uint64_t> seed, std::string& error);
    // Reads the placed models' files again, keeping the world as it is (a model saved
    // live); false with a one-line error keeps the last good models.
    bool reloadModels(std::string& error);
    // Every file the placed models were read from (glTF, buffers, images).
    std::vector<std::string> modelFiles() const;
    const std::vector<PlacedModel>& models() const { return models_; }
    // The placed models' punctual lights in world space. A model placed at scale s has its
    // point and spot lights' intensity × s², so it is lit as its file shows it.
    const std::vector<model::Light>& lights() const { return lights_; }
    // A glTF scene file's first camera, placed as its model is: where it is, where it
    // looks and its vertical field of view. False for a scene file (JSON: the box's view)
    // or a model without cameras.
    bool modelCamera(glm::vec3& eye, glm::vec3& forward, float& fovY) const;
    // The scene's bounds: the box's and the placed models'.
    glm::vec3 boundsMin() const { return boundsMin_; }
    glm::vec3 boundsMax() const { return boundsMax_; }
    // Changes whenever the lamp or a punctual light may have changed.
    uint64_t lightsVersion() const { return generation_ * 1'000'003ull + modelsVersion_; }
    void step() { sim_.step(); }
    void reset() { sim_.reset(); }
    double time() const { return sim_.time(); }
    double dt() const { return sim_.scene().physics.dt; }
    sim::World& sim() { return sim_; }
    const sim::World& sim() const { return sim_; }
    const SceneLook& look() const { return look_; }
    const std::string& file() const { return file_; }
    // Bumped by every successful load: the lamp and the meshes may have changed.
    uint64_t generation() const { return generation_; }

    // Pushes what changed since the last call into `renderer`: on a new generation the
    // look (meshes, walls, lamp), then bodies and particles whose sim versions moved.
    // `highlighted` is the picked tumbler (or −1).
    void writeTo(SceneRenderer& renderer, int highlighted);

private:
    bool loadModels(const sim::Scene&, const std::string& sceneFile, std::vector<PlacedModel>& out,
                    std::string& error) const;

    sim::World sim_;
    sim::Scene spec_;  // as last loaded: its models are read again by reloadModels
    void placeModels(std::vector<PlacedModel> models);

    std::vector<PlacedModel> models_;
    std::vector<model::Light> lights_;
    glm::vec3 boundsMin_{-1.0f}, boundsMax_{1.0f};
    uint64_t modelsVersion_ = 0, sentModels_ = 0;
    SceneLook look_;
    std::string file_;
    uint64_t generation_ = 0;
    // What the renderer last got.
    uint64_t sentGeneration_ = 0, sentBodies_ = ~0ull, sentParticles_ = ~0ull;
    uint64_t sentFireballs_ = ~0ull;  // the bodies version the particles were culled against
    int sentHighlight_ = -2;
};

}  // namespace kiln::scene
