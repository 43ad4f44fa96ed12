#include "app/live.hpp"

#include <chrono>
#include <set>

#include "app/app.hpp"
#include "kiln/log.hpp"

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
    watcher_->watch(canonical(app.runtime().pipelineFile()).parent_path());
    watcher_->watch(canonical(app.scene().file()).parent_path());
}

int LiveReload::poll(App& app) {
    if (!watcher_) return 0;
    auto changed = watcher_->poll();
    if (changed.empty()) return 0;
    Runtime& rt = app.runtime();
    const fs::path pipeline = canonical(rt.pipelineFile()), scene = canonical(app.scene().file());
    std::vector<fs::path> shaders;
    int reloads = 0;
    for (auto& path : changed) {
        const auto t0 = std::chrono::steady_clock::now();
        const std::string name = path.filename().string();
        if (path == pipeline) {
            std::string errors;
            if (rt.loadPipeline(path, errors)) {
                rt.setExternalError("pipeline", "");
                log::info("reloaded pipeline ", path.string(), " in ", msSince(t0), " ms");
                ++pipelineReloads, ++reloads;
            } else {
                if (!errors.empty() && errors.back() == '\n') errors.pop_back();
                rt.setExternalError("pipeline", errors + " (the previous pipeline keeps running)");
                log::error(errors);
                ++failures;
            }
        } else if (path == scene) {
            std::string error;
            if (app.scene().load(path.string(), app.seedOverride(), error)) {
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
            std::string error;
            if (rt.reloadModule(module, error)) {
                rt.setExternalError("module:" + module, "");
                log::info("reloaded module ", module, " in ", msSince(t0), " ms");
                ++moduleReloads, ++reloads;
            } else {
                rt.setExternalError("module:" + module, error + " (the previous module keeps running)");
                log::error(error);
                ++failures;
            }
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
