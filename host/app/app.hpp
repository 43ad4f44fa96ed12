// app/app.hpp — one running Kiln: the runtime, the world and the camera, stepped a
// frame at a time. Shared by the window and the headless front ends.
#pragma once

#include <memory>
#include <string>

#include "app/camera.hpp"
#include "app/cli.hpp"
#include "app/live.hpp"
#include "app/runtime.hpp"
#include "app/world.hpp"

namespace kiln::app {

class App {
public:
    bool init(const Options&, std::string& error);
    // Steps the simulation (unless paused), builds the scene view, runs the graph.
    void frame();
    // The graph output, or the texture chosen with --view / in the debug view.
    const TextureRef* displayedTexture() const;

    // The window's framebuffer changed size: reallocate size-relative textures.
    void resize(int width, int height);
    Runtime& runtime() { return runtime_; }
    World& world() { return world_; }
    OrbitCamera& camera() { return camera_; }
    LiveReload& live() { return live_; }
    uint64_t seed() const { return options_.seed; }
    bool paused = false;
    bool singleStep = false;
    std::string viewed;  // "pass.output" or empty for the graph output

private:
    SceneView buildView() const;

    Options options_;
    Runtime runtime_;
    World world_;
    OrbitCamera camera_;
    LiveReload live_;
    uint64_t frameIndex_ = 0;
    glm::mat4 lastViewProj_{0.0f};
    uint64_t sceneVersions_[6] = {};
};

int runWindow(const Options&);

}  // namespace kiln::app
