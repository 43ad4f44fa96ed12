// app/live.hpp — live editing: one file watcher over the shader roots, the pipeline's
// directory, the scene's directory and the module directories; each frame, settled
// changes are applied on the render thread (shaders rebuilt, pipeline recompiled,
// scene reset, module swapped). A mistake keeps the last good state and shows the
// error until it is fixed. Every reload is logged with how long it took.
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include "kiln/file_watcher.hpp"

namespace kiln::app {

class App;

class LiveReload {
public:
    void start(App& app);
    // Applies what changed since the last call; returns how many reloads happened.
    int poll(App& app);
    // Counters for tests and the debug view.
    int shaderReloads = 0, pipelineReloads = 0, sceneReloads = 0, moduleReloads = 0, failures = 0;

private:
    std::unique_ptr<FileWatcher> watcher_;
};

}  // namespace kiln::app
