// run/runtime.hpp — runs a compiled plan: adopts a new plan at a frame boundary
// (keeping what did not change), renders a frame, and decides per pass whether it
// runs or is skipped.
//
// Compile → cull → execute are three visible stages: the graph compiler (host/graph)
// produces a Plan; loadPipeline() swaps it in, keeping the pass objects and textures of
// passes whose signature did not change; renderFrame() executes the passes that run,
// skipping those whose inputs, parameters and scene categories are all unchanged since
// their last run. What it keeps per pass is a PassSlot (run/pass_slot.hpp).
//
// Every execute() runs under the guard (kiln/guard.hpp). A pass that faults — a fatal
// signal, an exception, the watchdog — is named once; its module is rolled back to the
// build it replaced, parameters kept, or its passes stay off until the file changes.
#pragma once

#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "graph/compiler.hpp"
#include "run/module_registry.hpp"
#include "run/pass_context.hpp"
#include "run/pass_slot.hpp"

namespace kiln::run {

struct RuntimeOptions {
    std::vector<std::filesystem::path> shaderRoots;
    std::vector<std::filesystem::path> moduleDirs;
    // Where a pipeline's relative "extends" is looked for after beside the file.
    std::vector<std::string> pipelineSearchDirs;
    int width = 720, height = 720;
    uint64_t textureBudgetBytes = 8ull << 30;  // all textures of a plan together
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
    // An edited description of the running pipeline (the debug view's toggles): the
    // file and its text stay what they were.
    bool loadPipelineDesc(graph::PipelineDesc, std::string& errors);
    // The debug view's parameter edit without a recompile: the value is checked against
    // its declaration (`error` says why not), written into the running plan and the
    // description, and the pass runs again next frame with the same object, programs
    // and textures. A parameter a texture's size is taken from recompiles (its textures
    // must be reallocated).
    bool setParam(const std::string& passId, const std::string& name, const ParamValue& value, std::string& error);
    // Textures the debug view shows or --dump wants ("pass.output"): un-culls their
    // producers without touching anyone's textures.
    void setRequested(std::vector<std::string> requested);
    // Parameter values from the command line (--set PASS.PARAM=VALUE), laid over every
    // pipeline file loaded from then on, live reloads included. Each is checked as the
    // file's values are; an error names the --set, not a place in the file. They become
    // part of the running description, so the debug view's write-back writes them too.
    using ParamOverride = graph::ParamOverride;
    void setOverrides(std::vector<ParamOverride> overrides) { overrides_ = std::move(overrides); }

    // New output size; refused (textures unchanged, `error` says why) when the plan's
    // textures would not fit the GL limits or the budget at that size.
    bool resize(int width, int height, std::string& error);
    // The voxel grids' shape (the scene's voxel volume, kiln::voxelGridShift): their
    // textures take the new sides where it changes. Refused like resize.
    bool setGridShape(const graph::GridShape& grid, std::string& error);
    const graph::GridShape& gridShape() const { return grid_; }

    void renderFrame(const SceneView& view, const SceneDraw& scene, const FrameInfo& frame);
    // Harvests finished GPU timer queries (renderFrame does it each frame; call after
    // a glFinish to get the last frames' times too).
    void collectGpuTimes();
    // Forgets every timing sample and ran/skipped count (benchmarks call it after warm-up).
    void resetTimings();
    // Runs every pass every frame regardless of versions (timing runs).
    bool alwaysRun = false;
    // Every output counts as read (PassContext::isRead): a dump writes them all.
    bool readEverything = false;
    // A pass has frames left that it asked for with keepRunning (its output is still
    // converging with nothing changed upstream).
    bool settling() const;
    // The CPU cost of the last renderFrame: all of it, and the part inside the passes'
    // execute(); the rest is the graph's own (version checks, state resets, timer
    // queries, uniform upload, bookkeeping).
    struct FrameCost {
        double frameMs = 0.0, passesMs = 0.0;
    };
    FrameCost lastFrameCost() const { return lastCost_; }

    // The graph output of the last frame (a colour 2D texture), or null.
    const TextureRef* outputTexture() const;
    const TextureRef* findTexture(std::string_view pass, std::string_view name) const;
    const graph::Plan* plan() const { return plan_ ? &*plan_ : nullptr; }
    const std::string& pipelineFile() const { return pipelineFile_; }
    // The pipeline file and the files it extends, in that order (graph::resolveExtends).
    const std::vector<std::filesystem::path>& pipelineChain() const { return pipelineChain_; }
    // The pipeline file's text as last loaded, and the description now running (the
    // loaded one with the debug view's edits).
    const std::string& pipelineText() const { return pipelineText_; }
    const graph::PipelineDesc* pipelineDesc() const { return desc_ ? &*desc_ : nullptr; }
    std::vector<PassRow> stats() const;
    std::string statsTable() const { return formatStatsTable(stats()); }
    std::vector<NamedTexture> textures() const;
    // One of textures() by its "pass.name", without listing them all.
    std::optional<NamedTexture> namedTexture(std::string_view qualified) const;
    bool dump(const std::filesystem::path& dir, std::string& error) const { return dumpTextures(textures(), dir, error); }

    // Live reload. Rebuilds every program that read one of `changedFiles` (absolute
    // paths); a failed build keeps the last good program and reports the mapped
    // error. Returns how many programs were rebuilt successfully.
    int reloadShaders(const std::vector<std::filesystem::path>& changedFiles);
    // Loads a fresh copy of module `name`; on success every pass of that module gets a
    // new object from it (parameters, the debug view's edits included, and textures
    // kept), and the old build is kept to roll back to should the new one fault.
    bool reloadModule(const std::string& name, std::string& error);
    bool usesModule(const std::string& name) const { return modules_ && modules_->uses(name); }
    // Errors from reloads outside the graph (scene file, module), shown until cleared.
    void setExternalError(const std::string& key, const std::string& message);

    ModuleLoader& loader() { return modules_->loader(); }
    const ShaderLibrary& shaders() const { return *shaders_; }
    // Errors currently standing (shader compile, pass failures), for the overlay.
    std::vector<std::string> activeErrors() const;
    // The running passes' programs' uses of more than OpenGL 4.5 guarantees
    // ("pass: file: what"), logged when each was built: they run here but would not
    // link on a driver at the minimum.
    std::vector<std::string> portabilityWarnings() const;

private:
    void adoptPlan(graph::Plan plan);
    std::unique_ptr<PassSlot> reuseOrCreateSlot(const graph::PlannedPass&, std::unique_ptr<PassSlot> old,
                                                 bool unchanged);
    void createPassObject(PassSlot&, const graph::PlannedPass&);
    void allocateTextures(size_t pass);
    std::vector<uint64_t> runKey(const graph::PlannedPass&, const PassSlot&, const SceneView&) const;
    bool runsForBodiesOnly(const graph::PlannedPass&, const PassSlot&, const std::vector<uint64_t>& key, bool settling,
                           const FrameInfo&) const;
    bool changedOnlyByInstances(const graph::PlannedPass&, const PassSlot&, const std::vector<uint64_t>& key,
                                bool converging) const;
    uint64_t inputSetup(const graph::Binding&) const;
    void runPass(size_t pass, const FrameResources&, const SceneView&, const FrameInfo&);
    void resetGlState() const;
    void retireFaultedObject(PassSlot&);
    void destroyPassObject(PassSlot&);
    void recreatePassObjects(const std::string& module);
    static std::string offUntilChanged(const LoadedModule&);
    void recoverFromFaults();
    void recompilePlan();
    bool applyOverrides(graph::PipelineDesc&, std::string& errors);

    RuntimeOptions options_;
    graph::GridShape grid_;
    std::unique_ptr<ModuleRegistry> modules_;
    std::unique_ptr<ShaderLibrary> shaders_;
    std::optional<graph::Plan> plan_;
    std::string pipelineText_, pipelineFile_;
    std::vector<std::filesystem::path> pipelineChain_;
    std::optional<graph::PipelineDesc> desc_;
    std::vector<ParamOverride> overrides_;
    FrameCost lastCost_, cost_;
    std::vector<std::string> requested_;
    std::vector<std::unique_ptr<PassSlot>> slots_;  // parallel to plan_->passes
    gl::Buffer frameUniforms_;
    gl::VertexArrayHandle emptyVao_;
    FallbackTextures fallbacks_;
    TextureLimits limits_;
    uint64_t versionCounter_ = 0;
    std::map<std::string, std::string> externalErrors_;
    std::set<std::string> faultedModules_;  // this frame's, recovered after it
    GLint frameGroupDepth_ = 0;             // KHR_debug group depth when the passes start
    float cameraFar_ = kCameraFar;          // the last frame's far plane (GpuFrame::proj)
    NamedTexture named(const std::string& pass, const std::string& name, const PooledTexture& t, bool read = true,
                       bool stale = false) const;
};

}  // namespace kiln::run
