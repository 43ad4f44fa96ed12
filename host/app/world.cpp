#include "app/world.hpp"

#include <filesystem>

namespace kiln::app {

World::World() = default;
World::~World() = default;

bool World::load(const std::string& sceneFile, uint64_t seed, std::string& error) {
    (void)seed;
    if (!std::filesystem::is_regular_file(sceneFile)) {
        error = sceneFile + ": scene file not found";
        return false;
    }
    firstSync_ = true;
    return true;
}

void World::step() { time_ += dt_; }

void World::sync(SceneRenderer& scene, uint64_t versions[6]) {
    if (firstSync_) {
        scene.setBox(box_);
        versions[sceneCategoryIndex(kSceneStatic)]++;
        versions[sceneCategoryIndex(kSceneLight)]++;
        firstSync_ = false;
    }
}

}  // namespace kiln::app
