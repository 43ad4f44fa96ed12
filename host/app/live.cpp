#include "app/live.hpp"

#include <chrono>
#include <algorithm>
#include <set>

#include "app/app.hpp"
#include "kiln/log.hpp"
#include "kiln/module_loader.hpp"

namespace fs = std::filesystem;

namespace kiln::app {

namespace {
bool isShader(const fs::path& p) {
    static const std::set<std::string> exts = {".glsl", ".vert", ".frag", ".geom", ".comp", ".tesc", ".tese"};
    return exts.count(p.extension().string()) > 0;
}
fs::path canonical(const fs::path& p) {
    std::error_code ec;
    fs::path c = fs::weakly_canonical(p, ec);
    return ec ? p : c;
}
double msSince(std::chrono::steady_clock::time_point t0) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}
}  // namespace

void LiveReload::start(App& app) {
    watcher_ = std::make_unique<FileWatcher>();
    for (auto& root : app.runtime().shaders().roots()) watcher_->watch(root);
    for (auto& dir : app.runtime().loader().dirs()) watcher_->watch(dir);
    // Pipelines and scenes are JSON files; their directories may hold anything.
    watchPipelineChain(app);
    watcher_->watch(canonical(app.scene().file()).parent_path(), FileWatcher::Depth::ThisDirectory, ".json");
    watchModels(app);
}

// The files the pipeline extends, wherever they are: a save to one reloads the pipeline.
void LiveReload::watchPipelineChain(App& app) {
    std::vector<fs::path> files = app.runtime().pipelineChain();
    files.push_back(app.runtime().pipelineFile());
    for (const fs::path& file : files)
        if (const fs::path dir = (canonical)(file).parent_path(); pipelineDirs_.insert(dir).second)
            watcher_->watch(dir, FileWatcher::Depth::ThisDirectory, ".json");
}

// The placed models' files (glTF, buffers, images): every file of their directories is
// watched, the ones the models were read from reload them.
void LiveReload::watchModels(App& app) {
    for (const std::string& file : app.scene().modelFiles()) {
        const fs::path dir = (canonical)(file).parent_path();
        if (std::find(modelDirs_.begin(), modelDirs_.end(), dir) != modelDirs_.end()) continue;
        modelDirs_.push_back(dir);
        watcher_->watch(dir, FileWatcher::Depth::ThisDirectory);
    }
}

namespace {
bool statFile(const fs::path& p, uintmax_t& size, fs::file_time_type& mtime) {
    std::error_code ec;
    size = fs::file_size(p, ec);
    if (ec) return false;
    mtime = fs::last_write_time(p, ec);
    return !ec;
}
}  // namespace

void LiveReload::reloadModule(App& app, const std::string& module, const fs::path& path) {
    Runtime& rt = app.runtime();
    const auto t0 = Clock::now();
    std::string error;
    if (rt.reloadModule(module, error)) {
        pendingModules_.erase(module);
        rt.setExternalError("module:" + module, "");
        log::info("reloaded module ", module, " in ", msSince(t0), " ms");
        ++moduleReloads;
        return;
    }
    std::string why;
    auto pending = pendingModules_.find(module);
    const bool withinWindow = pending == pendingModules_.end() || t0 - pending->second.firstFailure < kModuleRetryWindow;
    if (!ModuleLoader::checkFile(path, why) && withinWindow) {
        // Perhaps still being written: not loaded, not yet reported as broken.
        if (pending == pendingModules_.end()) {
            PendingModule p;
            p.path = path;
            p.firstFailure = t0;
            pending = pendingModules_.emplace(module, std::move(p)).first;
        }
        PendingModule& p = pending->second;
        p.error = error;
        p.stableSince = t0;
        p.triedThisVersion = true;
        statFile(path, p.size, p.mtime);
        rt.setExternalError("module:" + module, error + " (waiting for the file to be complete, retrying; "
                                                         "the previous module keeps running)");
        log::info("module ", module, " does not load yet (", why, "): retrying when the file settles");
        return;
    }
    pendingModules_.erase(module);
    rt.setExternalError("module:" + module, error + " (the previous module keeps running)");
    log::error(error);
    ++failures;
}

int LiveReload::retryModules(App& app) {
    const int before = moduleReloads;
    const auto now = Clock::now();
    std::vector<std::string> names;
    for (auto& [name, p] : pendingModules_) names.push_back(name);
    for (const std::string& name : names) {
        auto it = pendingModules_.find(name);
        if (it == pendingModules_.end()) continue;
        PendingModule& p = it->second;
        uintmax_t size = 0;
        fs::file_time_type mtime{};
        const bool exists = statFile(p.path, size, mtime);
        if (exists && (size != p.size || mtime != p.mtime)) {  // still growing: wait
            p.size = size, p.mtime = mtime, p.stableSince = now, p.triedThisVersion = false;
            continue;
        }
        if (now - p.firstFailure >= kModuleRetryWindow) {
            // Still invalid after the window: a broken module, reported once.
            const std::string error = p.error + " (still invalid " +
                                      std::to_string(kModuleRetryWindow.count() / 1000) +
                                      " s after it changed; the previous module keeps running)";
            app.runtime().setExternalError("module:" + name, error);
            log::error(p.error);
            ++failures;
            pendingModules_.erase(it);
            continue;
        }
        if (exists && !p.triedThisVersion && now - p.stableSince >= kModuleSettle) reloadModule(app, name, p.path);
    }
    return moduleReloads - before;
}

bool LiveReload::isModelFile(App& app, const fs::path& path) const {
    for (const std::string& file : app.scene().modelFiles())
        if (canonical(file) == path) return true;
    return false;
}

int LiveReload::poll(App& app) {
    if (!watcher_) return 0;
    const int retried = pendingModules_.empty() ? 0 : retryModules(app);
    auto changed = watcher_->poll();
    if (changed.empty()) return retried;
    Runtime& rt = app.runtime();
    const fs::path pipeline = canonical(rt.pipelineFile()), scene = canonical(app.scene().file());
    std::vector<fs::path> shaders;
    int reloads = retried;
    for (auto& path : changed) {
        const auto t0 = std::chrono::steady_clock::now();
        const std::string name = path.filename().string();
        const auto& chain = rt.pipelineChain();
        const bool inChain = std::any_of(chain.begin(), chain.end(), [&](const fs::path& f) { return (canonical)(f) == path; });
        if (path == pipeline || inChain) {
            std::string errors;
            if (rt.loadPipeline(pipeline, errors)) {
                watchPipelineChain(app);  // the chain may have grown
                rt.setExternalError("pipeline", "");
                log::info("reloaded pipeline ", path.string(), " in ", msSince(t0), " ms");
                ++pipelineReloads, ++reloads;
            } else {
                if (!errors.empty() && errors.back() == '\n') errors.pop_back();
                rt.setExternalError("pipeline", errors + " (the previous pipeline keeps running)");
                log::error(errors);
                ++failures;
            }
        } else if (path != scene && isModelFile(app, path)) {
            std::string error;
            if (app.scene().reloadModels(error)) {
                rt.setExternalError("scene", "");
                log::info("reloaded the models of ", app.scene().file(), " in ", msSince(t0), " ms");
                watchModels(app);
                ++sceneReloads, ++reloads;
            } else {
                rt.setExternalError("scene", error + " (the last good models stay)");
                log::error(error);
                ++failures;
            }
        } else if (path == scene) {
            std::string error;
            if (app.scene().load(path.string(), app.seedOverride(), error)) {
                watchModels(app);
                rt.setExternalError("scene", "");
                log::info("reloaded scene ", path.string(), " in ", msSince(t0), " ms");
                ++sceneReloads, ++reloads;
            } else {
                rt.setExternalError("scene", error + " (the previous world keeps running)");
                log::error(error);
                ++failures;
            }
        } else if (name.rfind("libpass_", 0) == 0 && path.extension() == ".so") {
            const std::string module = name.substr(8, name.size() - 11);
            if (!rt.usesModule(module)) continue;
            const int before = moduleReloads;
            reloadModule(app, module, path);
            reloads += moduleReloads - before;
        } else if (isShader(path)) {
            shaders.push_back(path);
        }
    }
    if (!shaders.empty()) {
        const auto t0 = std::chrono::steady_clock::now();
        const int rebuilt = rt.reloadShaders(shaders);
        if (rebuilt > 0) {
            log::info("reloaded ", rebuilt, " program(s) after editing ", shaders.front().filename().string(),
                      shaders.size() > 1 ? " and others" : "", " in ", msSince(t0), " ms");
            ++shaderReloads, ++reloads;
        }
    }
    return reloads;
}

}  // namespace kiln::app
