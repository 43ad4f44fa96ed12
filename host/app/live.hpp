// app/live.hpp — live editing: one file watcher over the shader roots, the pipeline's
// directory, the scene's directory and the module directories; each frame, settled
// changes are applied on the render thread (shaders rebuilt, pipeline recompiled,
// scene reset, module swapped). A mistake keeps the last good state and shows the
// error until it is fixed. Every reload is logged with how long it took.
#pragma once

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <vector>

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
    int applied() const { return shaderReloads + pipelineReloads + sceneReloads + moduleReloads; }

    // A module file that fails the ELF check may still be being written (a build cut in
    // the middle of writing, a copy in chunks): it is re-checked on the following polls
    // and reloaded once it has been unchanged for kModuleSettle and passes; if it still
    // fails kModuleRetryWindow after the first failure it is reported as broken.
    static constexpr std::chrono::milliseconds kModuleSettle{100};
    static constexpr std::chrono::milliseconds kModuleRetryWindow{3000};
    size_t pendingModules() const { return pendingModules_.size(); }

private:
    using Clock = std::chrono::steady_clock;
    struct PendingModule {
        std::filesystem::path path;
        std::string error;                        // the last check's error
        Clock::time_point firstFailure, stableSince;
        uintmax_t size = 0;                       // what the file looked like last poll
        std::filesystem::file_time_type mtime{};
        bool triedThisVersion = true;             // a reload was tried at this size + mtime
    };
    void reloadModule(App& app, const std::string& module, const std::filesystem::path& path);
    void watchModels(App& app);
    void watchPipelineChain(App& app);
    std::set<std::filesystem::path> pipelineDirs_;  // watched for the pipeline and the files it extends
    bool isModelFile(App& app, const std::filesystem::path& path) const;
    std::vector<std::filesystem::path> modelDirs_;  // watched for the placed models' files
    int retryModules(App& app);

    std::unique_ptr<FileWatcher> watcher_;
    std::map<std::string, PendingModule> pendingModules_;  // module name → retry state
};

}  // namespace kiln::app
