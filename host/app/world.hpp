// app/world.hpp — the bridge from the simulation (libkiln_sim) to the renderer:
// loads the scene file, steps the world, and hands bodies and particles to the
// scene renderer with a version bump per category that changed.
#pragma once

#include <cstdint>
#include <string>

#include "app/scene.hpp"
#include "kiln/sim/world.hpp"

namespace kiln::app {

class World {
public:
    // Loads `sceneFile`; on failure keeps the current world and returns false.
    bool load(const std::string& sceneFile, uint64_t seed, std::string& error);
    void step() { sim_.step(); }
    void reset() { sim_.reset(); }
    double time() const { return sim_.time(); }
    double dt() const { return sim_.scene().physics.dt; }
    const BoxLook& box() const { return box_; }
    const TumblerShapeParams& shape() const { return shape_; }
    sim::World& sim() { return sim_; }
    const std::string& file() const { return file_; }

    // Pushes what changed since the last call into `scene` and bumps `versions`
    // (indexed by SceneCategory bit) for each category that changed. `highlighted`
    // is the picked tumbler (or −1).
    void sync(SceneRenderer& scene, uint64_t versions[6], int highlighted);

private:
    sim::World sim_;
    BoxLook box_;
    TumblerShapeParams shape_;
    std::string file_;
    uint64_t seenBodies_ = ~0ull, seenParticles_ = ~0ull, generation_ = 0, seenGeneration_ = ~0ull;
    int seenHighlight_ = -2;
};

}  // namespace kiln::app
