// app/world.hpp — the bridge from the simulation (libkiln_sim) to the renderer:
// loads the scene file, steps the world, and hands bodies and particles to the
// scene renderer with a version bump per category that changed.
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include "app/scene.hpp"

namespace kiln::app {

class World {
public:
    World();
    ~World();
    bool load(const std::string& sceneFile, uint64_t seed, std::string& error);
    void step();
    double time() const { return time_; }
    double dt() const { return dt_; }
    const BoxLook& box() const { return box_; }
    const TumblerShapeParams& shape() const { return shape_; }
    // Pushes what changed since the last call into `scene` and bumps `versions`
    // (indexed by SceneCategory bit) for each category that changed.
    void sync(SceneRenderer& scene, uint64_t versions[6]);

private:
    BoxLook box_;
    TumblerShapeParams shape_;
    double time_ = 0.0, dt_ = 1.0 / 60.0;
    bool firstSync_ = true;
};

}  // namespace kiln::app
