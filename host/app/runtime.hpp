// app/runtime.hpp — runs a compiled plan: owns the pass objects, their textures,
// programs and framebuffers, decides per pass whether to run or skip, and times
// every pass on the GPU and the CPU.
//
// Compile → cull → execute are three visible stages: the graph compiler (host/graph)
// produces a Plan; loadPipeline() swaps it in at a frame boundary, keeping the pass
// objects and textures of passes whose signature did not change; renderFrame()
// executes the passes that run, skipping those whose inputs, parameters and scene
// categories are all unchanged since their last run.
#pragma once

#include <chrono>
#include <deque>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "app/scene.hpp"
#include "graph/compiler.hpp"
#include "kiln/module_loader.hpp"
#include "kiln/pass.hpp"

namespace kiln::app {

struct RuntimeOptions {
    std::vector<std::filesystem::path> shaderRoots;
    std::vector<std::filesystem::path> moduleDirs;
    int width = 720, height = 720;
};

struct PassRow {
    std::string id, module;
    std::string state;        // ran / skipped / culled / disabled / error / nothing to do
    std::string why;
    double gpuMs = -1.0;      // rolling average over the frames it ran (−1: none yet)
    double cpuMs = 0.0;
    double gpuMedianMs = -1.0, cpuMedianMs = 0.0;
    int ranFrames = 0, skippedFrames = 0;
};

class Runtime {
public:
    Runtime();
    ~Runtime();

    bool init(const RuntimeOptions&, std::string& error);

    // Compiles `file` and, on success, swaps the new plan in. On failure the running
    // plan stays and `errors` holds every diagnostic (with JSON paths).
    bool loadPipeline(const std::filesystem::path& file, std::string& errors);
    bool loadPipelineText(const std::string& text, const std::string& displayName, std::string& errors);
    // Textures the debug view shows or --dump wants ("pass.output"): un-culls their
    // producers without touching anyone's textures.
    void setRequested(std::vector<std::string> requested);
    void resize(int width, int height);

    void renderFrame(const SceneView& view, const FrameInfo& frame);
    // Harvests finished GPU timer queries (renderFrame does it each frame; call after
    // a glFinish to get the last frames' times too).
    void collectGpuTimes();
    // Forgets every timing sample and ran/skipped count (benchmarks call it after warm-up).
    void resetTimings();
    // Runs every pass every frame regardless of versions (timing runs).
    bool alwaysRun = false;

    // The graph output of the last frame (a colour 2D texture), or 0.
    const TextureRef* outputTexture() const;
    const TextureRef* findTexture(std::string_view pass, std::string_view name) const;
    const graph::Plan* plan() const { return plan_ ? &*plan_ : nullptr; }
    const std::string& pipelineFile() const { return pipelineFile_; }
    const std::string& pipelineText() const { return pipelineText_; }
    std::vector<PassRow> stats() const;
    std::string statsTable() const;

    struct TextureInfo { std::string pass, name; bool internal; TextureRef ref; };
    std::vector<TextureInfo> textures() const;
    // Writes every texture of the last frame into `dir`: PNG (clamped to [0,1]) and,
    // for float and depth formats, PFM with the raw values. 3D textures: the middle
    // slice of level 0.
    bool dump(const std::filesystem::path& dir, std::string& error) const;

    // Live reload. Rebuilds every program that read one of `changedFiles` (absolute
    // paths); a failed build keeps the last good program and reports the mapped
    // error. Returns how many programs were rebuilt successfully.
    int reloadShaders(const std::vector<std::filesystem::path>& changedFiles);
    // Loads a fresh copy of module `name`; on success every pass of that module gets a
    // new object from it (parameters and textures kept) and the old library goes.
    bool reloadModule(const std::string& name, std::string& error);
    bool usesModule(const std::string& name) const { return modules_.count(name) > 0; }
    // Errors from reloads outside the graph (scene file, module), shown until cleared.
    void setExternalError(const std::string& key, const std::string& message);

    SceneRenderer& scene() { return scene_; }
    ModuleLoader& loader() { return *loader_; }
    const ShaderLibrary& shaders() const { return *shaders_; }
    // Errors currently standing (shader compile, pass failures), for the overlay.
    std::vector<std::string> activeErrors() const;

private:
    struct TextureSlot {
        TextureDecl decl;
        gl::Texture texture;
        TextureRef ref;
        uint64_t version = 0;
        bool internal = false;
    };
    struct ProgramEntry {
        ProgramDesc desc;  // as built (defines included), to rebuild on a shader edit
        gl::ProgramHandle program;  // the last good one; kept while an edit is broken
        std::string error;
        std::vector<std::filesystem::path> dependencies;
    };
    struct PassSlot {
        std::string id, module;
        uint64_t signature = 0;
        std::shared_ptr<LoadedModule> library;
        PassPtr pass;
        std::map<std::string, TextureSlot, std::less<>> textures;
        std::map<std::string, gl::FramebufferHandle> framebuffers;
        std::map<std::string, ProgramEntry> programs;
        uint64_t programGeneration = 0;  // bumped when a program is (re)built: the pass runs again
        std::optional<std::vector<uint64_t>> lastRunKey;
        std::string error;
        gl::GpuTimer timer;
        std::deque<double> gpuSamples, cpuSamples;
        int ranFrames = 0, skippedFrames = 0;
        std::string lastState = "not run", lastWhy;
    };
    class Context;
    friend class Context;

    struct ModuleInfo { std::shared_ptr<LoadedModule> library; PassDeclaration decl; };
    graph::Result<PassDeclaration> declarationOf(const std::string& module);
    void adoptPlan(graph::Plan plan);
    void allocateTextures(PassSlot& slot, const graph::PlannedPass& planned);
    const TextureRef& fallback(TextureKind, Fallback) const;
    std::vector<uint64_t> runKey(const graph::PlannedPass&, const PassSlot&, const SceneView&) const;
    void recompilePlan();

    RuntimeOptions options_;
    std::unique_ptr<ModuleLoader> loader_;
    std::unique_ptr<ShaderLibrary> shaders_;
    std::map<std::string, ModuleInfo> modules_;
    std::optional<graph::Plan> plan_;
    std::string pipelineText_, pipelineFile_;
    std::vector<std::string> requested_;
    std::vector<std::unique_ptr<PassSlot>> slots_;  // parallel to plan_->passes
    SceneRenderer scene_;
    gl::Buffer frameUniforms_;
    gl::VertexArrayHandle emptyVao_;
    struct Fallbacks { gl::Texture black, white, flatNormal, farDepth, black3d; TextureRef refs[5]; } fallbacks_;
    uint64_t versionCounter_ = 0;
    std::map<std::string, std::string> externalErrors_;
};

}  // namespace kiln::app
