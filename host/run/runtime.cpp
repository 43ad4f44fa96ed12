#include "run/runtime.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <sstream>

#include "graph/compiler.hpp"
#include "graph/pipeline.hpp"
#include "kiln/guard.hpp"
#include "kiln/log.hpp"

namespace fs = std::filesystem;

namespace kiln::run {

namespace {
// Units the host unbinds before each pass: more than any shipped pass uses; GL 4.5
// guarantees 80 texture and 8 image units.
constexpr GLsizei kResetTextureUnits = 16;
constexpr GLsizei kResetImageUnits = 8;
}  // namespace

Runtime::Runtime() = default;
Runtime::~Runtime() {
    // Pass objects go before the modules whose code destroys them (PassPtr keeps its
    // module alive), and before the GL objects they might reference.
    for (auto& slot : slots_) destroyPassObject(*slot);
    slots_.clear();
    if (modules_) modules_->clear();
}

bool Runtime::init(const RuntimeOptions& options, std::string& error) {
    options_ = options;
    modules_ = std::make_unique<ModuleRegistry>(options.moduleDirs);
    shaders_ = std::make_unique<ShaderLibrary>(options.shaderRoots);
    if (shaders_->resolve("common/frame.glsl").empty()) {
        error = "shader root without common/frame.glsl; looked in: ";
        for (auto& r : options.shaderRoots) error += r.string() + " ";
        return false;
    }
    frameUniforms_ = gl::Buffer::create(sizeof(GpuFrame), nullptr, GL_DYNAMIC_STORAGE_BIT, "kiln.frame");
    emptyVao_ = gl::createVertexArray();
    fallbacks_.create();
    limits_ = TextureLimits::query(options.textureBudgetBytes);
    return true;
}

bool Runtime::loadPipeline(const fs::path& file, std::string& errors) {
    std::string text, why;
    if (!graph::readPipelineFile(file.string(), text, why)) {
        errors = file.string() + ": " + why;
        return false;
    }
    return loadPipelineText(text, file.string(), errors);
}

bool Runtime::loadPipelineText(const std::string& text, const std::string& displayName, std::string& errors) {
    auto parsed = graph::parsePipeline(text, displayName);
    if (!parsed) {
        errors = parsed.errorText();
        return false;
    }
    // The files it extends are read relative to it, with the same bounds as the first.
    std::vector<std::string> chain;
    auto resolved = graph::resolveExtends(std::move(*parsed), graph::readPipelineFile, &chain, options_.pipelineSearchDirs);
    if (!resolved) {
        errors = resolved.errorText();
        return false;
    }
    if (!applyOverrides(*resolved, errors) || !loadPipelineDesc(std::move(*resolved), errors)) return false;
    pipelineText_ = text;
    pipelineFile_ = displayName;
    pipelineChain_.assign(chain.begin(), chain.end());
    return true;
}

bool Runtime::applyOverrides(graph::PipelineDesc& desc, std::string& errors) {
    std::vector<std::string> ids;
    for (const graph::PassDesc& p : desc.passes) ids.push_back(p.id);
    for (const ParamOverride& o : overrides_) {
        const std::string origin = "--set " + o.text + ": ";
        const int index = desc.find(o.pass);
        if (index < 0) {
            errors = origin + "no pass \"" + o.pass + "\" in " + desc.fileName + suggestion(o.pass, ids, "passes");
            return false;
        }
        graph::PassDesc& pass = desc.passes[size_t(index)];
        auto decl = modules_->declaration(pass.module);
        if (!decl) continue;  // the compiler names the module's problem, at its place in the file
        std::vector<std::string> names;
        for (const ParamDecl& d : decl->params) names.push_back(d.name);
        auto param = std::find_if(decl->params.begin(), decl->params.end(), [&](const ParamDecl& d) { return d.name == o.param; });
        if (param == decl->params.end()) {
            errors = origin + "module " + pass.module + " has no parameter \"" + o.param + "\"" +
                     suggestion(o.param, names, "parameters");
            return false;
        }
        std::string problem;
        const std::optional<ParamValue> value = graph::checkParamLiteral(graph::parseParamLiteral(o.value), *param, problem);
        if (!value) {
            errors = origin + problem;
            return false;
        }
        graph::setParamLiteral(pass, o.param, *value);
    }
    return true;
}

bool Runtime::loadPipelineDesc(graph::PipelineDesc desc, std::string& errors) {
    graph::CompileOptions opt;
    opt.resolve = [this](const std::string& m) { return modules_->declaration(m); };
    opt.availableModules = modules_->loader().available();
    opt.requested = requested_;
    auto result = graph::compile(desc, opt);
    if (!result) {
        errors = result.errorText();
        return false;
    }
    if (std::string tooLarge = checkTextureLimits(*result, options_.width, options_.height, limits_, grid_); !tooLarge.empty()) {
        errors = tooLarge;
        return false;
    }
    for (auto& w : result->warnings) log::warn(w.str());
    desc_ = std::move(desc);
    adoptPlan(std::move(*result));
    return true;
}

bool Runtime::setParam(const std::string& passId, const std::string& name, const ParamValue& value, std::string& error) {
    const int index = plan_ ? plan_->find(passId) : -1;
    const int descIndex = desc_ ? desc_->find(passId) : -1;
    if (index < 0 || descIndex < 0) {
        error = "no pass \"" + passId + "\" in the running pipeline";
        return false;
    }
    graph::PlannedPass& planned = plan_->passes[size_t(index)];
    auto decl = std::find_if(planned.decl.params.begin(), planned.decl.params.end(),
                             [&](const ParamDecl& d) { return d.name == name; });
    if (decl == planned.decl.params.end()) {
        error = passId + ": module " + planned.module + " has no parameter \"" + name + "\"";
        return false;
    }
    std::string problem;
    std::optional<ParamValue> checked = graph::checkParamValue(value, *decl, problem);
    if (!checked) {
        error = passId + ".params." + name + ": " + problem;
        return false;
    }
    // A parameter that sizes a texture, or decides whether an output is filled (which a
    // binding may need), goes through the whole compiler: an invalid graph is refused
    // and the running one kept.
    const bool shapesThePlan = [&] {
        for (const auto* list : {&planned.decl.outputs, &planned.decl.internals})
            for (const TextureDecl& t : *list)
                if (((t.size.mode == SizeRule::Mode::FromParam || t.size.mode == SizeRule::Mode::RelativeOverParam) &&
                     (t.size.source == name || t.size.capSource == name)) ||
                    t.producedWhen.param == name)
                    return true;
        return false;
    }();
    if (shapesThePlan) {
        graph::PipelineDesc edited = *desc_;
        graph::setParamLiteral(edited.passes[size_t(descIndex)], name, *checked);
        return loadPipelineDesc(std::move(edited), error);
    }
    graph::setParamLiteral(desc_->passes[size_t(descIndex)], name, *checked);
    *planned.params.find(name) = *checked;
    slots_[size_t(index)]->invalidate(false);
    return true;
}

void Runtime::setRequested(std::vector<std::string> requested) {
    if (requested == requested_) return;
    requested_ = std::move(requested);
    recompilePlan();
}

void Runtime::recompilePlan() {
    if (!desc_) return;
    std::string errors;
    if (!loadPipelineDesc(*desc_, errors)) log::error(errors);
}

void Runtime::adoptPlan(graph::Plan plan) {
    const graph::PlanDiff diff = plan_ ? graph::diffPlans(*plan_, plan) : graph::PlanDiff{};
    std::map<std::string, std::unique_ptr<PassSlot>> old;
    for (auto& s : slots_) old[s->id] = std::move(s);
    std::vector<std::unique_ptr<PassSlot>> next;
    for (auto& planned : plan.passes) {
        auto it = old.find(planned.id);
        std::unique_ptr<PassSlot> previous;
        if (it != old.end()) previous = std::move(it->second);
        next.push_back(reuseOrCreateSlot(planned, std::move(previous), diff.isUnchanged(planned.id)));
    }
    for (auto& [id, dropped] : old)
        if (dropped) destroyPassObject(*dropped);
    slots_ = std::move(next);
    plan_ = std::move(plan);
    for (size_t i = 0; i < slots_.size(); ++i) allocateTextures(i);
    log::info("pipeline ", plan_->fileName, ": ", plan_->runOrder().size(), " of ", plan_->passes.size(),
              " passes run; ", diff.unchanged.size(), " unchanged, ", diff.changed.size(),
              " changed in module, parameters or inputs");
}

// A pass whose id and signature (module, parameters, inputs) are unchanged keeps
// everything: object, textures, programs, skip state. One of the same module whose
// parameters or inputs changed keeps its textures where their shape is the same
// (allocateTextures decides) and its programs, but gets a fresh object and runs again.
// Anything else starts fresh.
std::unique_ptr<PassSlot> Runtime::reuseOrCreateSlot(const graph::PlannedPass& planned,
                                                     std::unique_ptr<PassSlot> slot, bool unchanged) {
    if (!slot || slot->module != planned.module) {
        if (slot) destroyPassObject(*slot);
        slot = std::make_unique<PassSlot>();
        slot->id = planned.id;
        slot->module = planned.module;
    } else if (!unchanged) {
        destroyPassObject(*slot);  // its cached decisions were made for other parameters
        slot->error.clear();
    }
    slot->signature = planned.signatureHash;
    if (planned.state == graph::PassState::Disabled) {
        slot->textures.clear();
        slot->framebuffers.clear();
    } else if (!slot->pass) {
        createPassObject(*slot, planned);
    }
    return slot;
}

void Runtime::createPassObject(PassSlot& slot, const graph::PlannedPass& planned) {
    const ModuleRegistry::Module* module = modules_->find(planned.module);
    std::string error = "module " + planned.module + " is not loaded";
    destroyPassObject(slot);
    if (module && module->library->faulted()) {
        slot.library = module->library;  // activeErrors names the fault
        error = module->library->fault();
    } else if (module) {
        slot.library = module->library;
        slot.pass = ModuleLoader::create(module->library, error);
    }
    slot.error = slot.pass ? std::string() : error;
    slot.invalidate(false);
}

// The library's destroy() runs under the guard; a fault there is printed once, and
// marks the library (no object is created from it again).
void Runtime::destroyPassObject(PassSlot& slot) {
    if (!slot.pass) return;
    slot.pass.reset();
    if (slot.library && slot.library->takeFaultToReport()) log::error(slot.library->fault());
}

void Runtime::allocateTextures(size_t i) {
    const graph::PlannedPass& planned = plan_->passes[i];
    PassSlot& slot = *slots_[i];
    if (planned.state == graph::PassState::Disabled) return;
    bool changed = false;
    auto want = [&](const TextureDecl& d, bool internal) {
        const graph::Extent e = plan_->extentOf(static_cast<int>(i), d.name, options_.width, options_.height, grid_);
        changed |= ensureTexture(slot.textures, d, e, internal, slot.id + "." + d.name, ++versionCounter_);
    };
    for (auto& d : planned.decl.outputs) want(d, false);
    for (auto& d : planned.decl.internals) want(d, true);
    // Textures the declaration no longer has (a reloaded module renamed one) go.
    changed |= std::erase_if(slot.textures, [&](auto& entry) { return !planned.texture(entry.first); }) > 0;
    if (changed) slot.invalidate(true);
}

bool Runtime::resize(int width, int height, std::string& error) {
    width = std::max(1, width), height = std::max(1, height);
    if (width == options_.width && height == options_.height) return true;
    if (plan_) {
        error = checkTextureLimits(*plan_, width, height, limits_, grid_);
        if (!error.empty()) return false;  // the textures keep their size
    }
    options_.width = width;
    options_.height = height;
    if (!plan_) return true;
    // In order: a texture sized from an input follows its producer's new size.
    for (size_t i = 0; i < slots_.size(); ++i) allocateTextures(i);
    return true;
}

bool Runtime::setGridShape(const graph::GridShape& grid, std::string& error) {
    if (grid == grid_) return true;
    if (plan_) {
        error = checkTextureLimits(*plan_, options_.width, options_.height, limits_, grid);
        if (!error.empty()) return false;
    }
    grid_ = grid;
    if (plan_)
        for (size_t i = 0; i < slots_.size(); ++i) allocateTextures(i);
    return true;
}

std::vector<uint64_t> Runtime::runKey(const graph::PlannedPass& planned, const PassSlot& slot,
                                      const SceneView& view) const {
    // Everything whose change must make the pass run again: each input's version
    // (0 for a fallback), each scene category it reads, the output size, the
    // generation of its programs (a rebuilt program runs the pass again), and which of
    // its outputs are read (one it left unwritten must be written once read).
    std::vector<uint64_t> key;
    for (auto& b : planned.bindings) {
        uint64_t version = 0;
        if (b.bound()) {
            const PassSlot& producer = *slots_[static_cast<size_t>(b.producer)];
            auto it = producer.textures.find(b.output);
            if (it != producer.textures.end()) version = it->second.version;
        }
        key.push_back(version);
    }
    for (int i = 0; i < kSceneCategoryCount; ++i)
        key.push_back((planned.decl.reads & (1u << i)) ? view.versions[i] : 0);
    key.push_back(static_cast<uint64_t>(options_.width) << 32 | static_cast<uint32_t>(options_.height));
    key.push_back(slot.programs.generation());
    uint64_t read = 0;
    for (size_t k = 0; k < planned.outputRead.size() && k < 64; ++k)
        if (readEverything || planned.outputRead[k]) read |= uint64_t(1) << k;
    key.push_back(read);
    return key;
}

namespace {
// Whether this run's key differs from the last run's (runKey: the inputs' versions, the
// scene categories, the output size, the programs) only in scene categories of
// `categories` and in inputs `inputExplained(k)` accepts; never for a pass that reads
// time or did not run last time (or failed).
template <class InputExplained>
bool changedOnlyIn(const graph::PlannedPass& planned, const std::optional<std::vector<uint64_t>>& lastKey,
                   const std::vector<uint64_t>& key, uint32_t categories, InputExplained&& inputExplained) {
    if (planned.decl.timeDependent || !lastKey || lastKey->size() != key.size()) return false;
    const size_t inputs = planned.bindings.size(), scene = inputs + kSceneCategoryCount;
    for (size_t k = 0; k < key.size(); ++k) {
        if (key[k] == (*lastKey)[k]) continue;
        if (k >= scene) return false;  // the output size or the programs
        if (k >= inputs ? !((1u << (k - inputs)) & categories) : !inputExplained(k)) return false;
    }
    return true;
}
}  // namespace

// Whether the only reasons this pass runs are bodies moving (kiln/pass.hpp, REDRAWING
// PART OF THE PICTURE): the frame says only bodies moved, the pass ran last time, and
// what differs from that run's key is scene categories it reads (not time) or inputs
// whose producers last ran for the same reason. A parameter, a program, a size, a
// failed or settling run, time itself, or an input a producer rewrote for another
// reason: everything.
bool Runtime::runsForBodiesOnly(const graph::PlannedPass& planned, const PassSlot& slot,
                                const std::vector<uint64_t>& key, bool settling, const FrameInfo& frame) const {
    return frame.redrawCount > 0 && !settling &&
           changedOnlyIn(planned, slot.lastRunKey, key, kSceneAll & ~kSceneTime, [&](size_t k) {
               const graph::Binding& b = planned.bindings[k];
               return b.bound() && slots_[static_cast<size_t>(b.producer)]->lastRunByScene;
           });
}

// Whether this run's outputs differ from the last run's only through instances moving
// (kiln/pass.hpp, REUSING WHAT DID NOT CHANGE): the pass ran last time and was not
// still converging, it does not read time, and what differs from that run's key is
// instance categories it reads or inputs whose setup is what it was then.
bool Runtime::changedOnlyByInstances(const graph::PlannedPass& planned, const PassSlot& slot,
                                     const std::vector<uint64_t>& key, bool converging) const {
    return !converging && slot.inputSetups.size() == planned.bindings.size() &&
           changedOnlyIn(planned, slot.lastRunKey, key, kSceneBodies | kSceneParticles, [&](size_t k) {
               return inputSetup(planned.bindings[k]) == slot.inputSetups[k];
           });
}

uint64_t Runtime::inputSetup(const graph::Binding& b) const {
    return b.bound() ? slots_[static_cast<size_t>(b.producer)]->setup : 0;
}

void Runtime::renderFrame(const SceneView& view, const SceneDraw& scene, const FrameInfo& frameIn) {
    const auto start = std::chrono::steady_clock::now();
    cost_ = {};
    struct Done {  // on every return
        Runtime& rt;
        std::chrono::steady_clock::time_point start;
        ~Done() {
            rt.cost_.frameMs = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
            rt.lastCost_ = rt.cost_;
        }
    } done{*this, start};
    FrameInfo frame = frameIn;
    frame.outputWidth = options_.width;
    frame.outputHeight = options_.height;
    GpuFrame gpuFrame = view.frame;
    // A perspective projection's far plane: proj[3][2] / (proj[2][2] + 1) (glm::perspective).
    if (const glm::mat4& p = view.frame.proj; p[2][3] == -1.0f && p[2][2] != -1.0f) {
        const float far = p[3][2] / (p[2][2] + 1.0f);
        if (std::isfinite(far) && far > 0.0f) cameraFar_ = far;
    }
    gpuFrame.outputSize = {float(options_.width), float(options_.height), 1.0f / float(options_.width),
                           1.0f / float(options_.height)};
    gpuFrame.time = {float(frame.time), float(frame.dt), float(frame.index), 0.0f};
    glNamedBufferSubData(frameUniforms_.id(), 0, sizeof(GpuFrame), &gpuFrame);
    collectGpuTimes();
    if (!plan_) return;
    const FrameResources shared{slots_, fallbacks_, *shaders_, scene, emptyVao_.id(), readEverything};
    glGetIntegerv(GL_DEBUG_GROUP_STACK_DEPTH, &frameGroupDepth_);  // a faulted pass's groups are popped to it
    for (size_t i = 0; i < slots_.size(); ++i) runPass(i, shared, view, frame);
    recoverFromFaults();
}

// The barrier between passes is the host's, not each producer's: after a pass runs,
// whatever it wrote (image stores, attachments, copies) is made visible to every way a
// later pass or a read-back can read it. No slot declares how it is read (fetch, image
// load, attachment), so the host covers them all; a barrier with nothing outstanding
// costs little. Barriers between a pass's own dispatches stay the pass's.
constexpr GLbitfield kWrittenVisibleToLaterPasses = GL_TEXTURE_FETCH_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT |
                                                    GL_TEXTURE_UPDATE_BARRIER_BIT | GL_FRAMEBUFFER_BARRIER_BIT |
                                                    GL_PIXEL_BUFFER_BARRIER_BIT;

void Runtime::runPass(size_t i, const FrameResources& shared, const SceneView& view, const FrameInfo& frame) {
    PassSlot& slot = *slots_[i];
    const graph::PlannedPass& planned = plan_->passes[i];
    PassTimings& t = slot.timings;
    if (planned.state != graph::PassState::Run) return t.note(graph::toString(planned.state), planned.reason);
    if (slot.pass && slot.library && slot.library->faulted()) retireFaultedObject(slot);  // another pass of it faulted
    if (!slot.pass) return t.note("error", slot.error);
    const auto key = runKey(planned, slot, view);
    const bool unchanged = !planned.decl.timeDependent && slot.lastRunKey == key && slot.error.empty();
    const bool settling = unchanged && slot.settlingFrames > 0;  // counted under alwaysRun too
    if (unchanged && !settling && !alwaysRun) {
        ++t.skippedFrames;
        return t.note("skipped", "inputs, parameters and scene unchanged");
    }
    FrameInfo passFrame = frame;
    if (!runsForBodiesOnly(planned, slot, key, settling, frame)) passFrame.redrawCount = 0;
    const bool byInstances = changedOnlyByInstances(planned, slot, key, slot.settlingFrames > 0);
    if (settling) --slot.settlingFrames;
    else slot.settlingFrames = 0;  // a change: the pass says again whether it needs more frames

    resetGlState();
    shared.scene.bindInstances();
    slot.error.clear();
    HostPassContext ctx(shared, slot, planned, view, passFrame);
    if (settling) ctx.markSettling();
    const auto cpuStart = std::chrono::steady_clock::now();
    std::optional<std::string> fault;
    {
        gl::DebugGroup group(slot.id);
        t.timer.begin();
        fault = guard::guarded([&] { slot.pass->execute(ctx); }, slot.library->watch());
        glMemoryBarrier(kWrittenVisibleToLaterPasses);
        if (fault) {
            // What the pass left open is closed: its debug groups, its bindings.
            // (The host's own group for the pass stays: `group` pops it.)
            for (GLint d = 0; glGetIntegerv(GL_DEBUG_GROUP_STACK_DEPTH, &d), d > frameGroupDepth_ + 1;) glPopDebugGroup();
            resetGlState();
        }
        t.timer.end();
    }
    const double cpuMs = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - cpuStart).count();
    t.addCpu(cpuMs);
    cost_.passesMs += cpuMs;

    if (fault) {
        slot.library->markFaulted(str("pass \"", slot.id, "\" (", slot.library->sourcePath().filename().string(),
                                      "): ", *fault, " in execute()"));
        retireFaultedObject(slot);
        faultedModules_.insert(slot.module);
        return t.note("error", slot.error);
    }
    if (ctx.failed()) {
        slot.lastRunKey.reset();
        if (slot.error != slot.loggedError) log::error(slot.id, ": ", slot.loggedError = slot.error);
        return t.note("error", slot.error);
    }
    slot.loggedError.clear();
    ++t.ranFrames;
    slot.lastRunKey = runKey(planned, slot, view);
    // A pass still converging after a change that touched everything (keepRunning:
    // voxel bounces fed back) changes its outputs everywhere for that many runs more,
    // whatever moved since.
    bool byScene = passFrame.redrawCount > 0;
    if (!byScene) slot.convergingRuns = slot.settlingFrames;
    else if (slot.convergingRuns > 0) --slot.convergingRuns, byScene = false;
    slot.lastRunByScene = byScene;
    if (ctx.nothing()) return t.note("nothing to do", *ctx.nothing());
    std::string why = slot.settlingFrames > 0 ? str("settling (", slot.settlingReason, "): ", slot.settlingFrames,
                                                    slot.settlingFrames == 1 ? " more frame" : " more frames")
                                              : std::string();
    if (passFrame.redrawCount > 0) {
        ++t.partialFrames;
        double pixels = 0.0;
        for (int r = 0; r < passFrame.redrawCount; ++r)
            pixels += double(passFrame.redraw[r].width) * passFrame.redraw[r].height;
        why = str("bodies moved: ", int(std::lround(100.0 * pixels / (double(frame.outputWidth) * frame.outputHeight))),
                  " % of the picture to redraw");
    }
    t.note("ran", why);
    if (!byInstances) slot.setup = ++versionCounter_;
    slot.inputSetups.clear();
    for (auto& b : planned.bindings) slot.inputSetups.push_back(inputSetup(b));
    for (auto& [name, tex] : slot.textures) tex.version = ++versionCounter_, tex.ref.setup = slot.setup;
}

// A clean slate for every pass, so one pass's GL state never leaks into the next
// (the list is the pass manual's, kiln/pass.hpp "GL STATE").
void Runtime::resetGlState() const {
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glViewport(0, 0, options_.width, options_.height);
    glDisable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glDepthMask(GL_TRUE);
    glDisable(GL_BLEND);
    glBlendFunc(GL_ONE, GL_ZERO);
    glDisable(GL_CULL_FACE);
    glCullFace(GL_BACK);
    glDisable(GL_POLYGON_OFFSET_FILL);
    glPolygonOffset(0.0f, 0.0f);
    glDisable(GL_SCISSOR_TEST);
    glDisable(GL_STENCIL_TEST);
    glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    glUseProgram(0);
    glBindVertexArray(0);
    glBindTextures(0, kResetTextureUnits, nullptr);
    glBindImageTextures(0, kResetImageUnits, nullptr);
    glBindBufferBase(GL_UNIFORM_BUFFER, kFrameBinding, frameUniforms_.id());
}

void Runtime::collectGpuTimes() {
    for (auto& s : slots_) s->timings.collectGpu();
}

void Runtime::resetTimings() {
    for (auto& s : slots_) s->timings.reset();
}

const TextureRef* Runtime::outputTexture() const {
    if (!plan_ || !plan_->output.valid()) return nullptr;
    const PassSlot& slot = *slots_[static_cast<size_t>(plan_->output.pass)];
    auto it = slot.textures.find(plan_->output.name);
    return it == slot.textures.end() ? nullptr : &it->second.ref;
}

const TextureRef* Runtime::findTexture(std::string_view pass, std::string_view name) const {
    for (auto& s : slots_) {
        if (s->id != pass) continue;
        auto it = s->textures.find(name);
        return it == s->textures.end() ? nullptr : &it->second.ref;
    }
    return nullptr;
}

std::optional<NamedTexture> Runtime::namedTexture(std::string_view qualified) const {
    const size_t dot = qualified.find('.');
    if (dot == std::string_view::npos) return std::nullopt;
    for (auto& s : slots_) {
        if (s->id != qualified.substr(0, dot)) continue;
        auto it = s->textures.find(qualified.substr(dot + 1));
        if (it == s->textures.end()) return std::nullopt;
        const PooledTexture& t = it->second;
        return named(s->id, it->first, t);
    }
    return std::nullopt;
}

bool Runtime::settling() const {
    return std::any_of(slots_.begin(), slots_.end(), [](const auto& slot) { return slot->settlingFrames > 0; });
}

std::vector<PassRow> Runtime::stats() const {
    std::vector<PassRow> rows;
    for (auto& s : slots_) rows.push_back(s->timings.row(s->id, s->module));
    return rows;
}

NamedTexture Runtime::named(const std::string& pass, const std::string& name, const PooledTexture& t, bool read,
                            bool stale) const {
    NamedTexture n{pass, name, t.internal, t.ref, t.decl.depthNear, t.decl.depthFar, t.decl.size.tiles, read, stale};
    n.cameraDepth = t.decl.depthNear == kCameraNear && t.decl.depthFar == kCameraFar;
    if (n.cameraDepth) n.depthFar = cameraFar_;
    return n;
}

std::vector<NamedTexture> Runtime::textures() const {
    std::vector<NamedTexture> out;
    for (size_t i = 0; i < slots_.size(); ++i) {
        const PassSlot& s = *slots_[i];
        const graph::PlannedPass* planned = plan_ && i < plan_->passes.size() ? &plan_->passes[i] : nullptr;
        for (auto& [name, t] : s.textures) {
            const bool read = !planned || t.internal || readEverything || planned->outputIsRead(name);
            out.push_back(named(s.id, name, t, read, !read && t.decl.onlyWhenRead));
        }
    }
    return out;
}

std::vector<std::string> Runtime::activeErrors() const {
    std::vector<std::string> errors;
    for (auto& [key, message] : externalErrors_) errors.push_back(message);
    std::set<const LoadedModule*> faultsNamed;
    for (auto& s : slots_) {
        // A faulted module's error stands once, as the module's, not once per pass;
        // recoverFromFaults has usually put it among the external errors already.
        if (s->library && s->library->faulted()) {
            if (faultsNamed.insert(s->library.get()).second && !externalErrors_.count("module:" + s->module))
                errors.push_back(s->library->fault() + offUntilChanged(*s->library));
        } else if (!s->error.empty()) {
            errors.push_back(s->id + ": " + s->error);
        }
        for (auto& e : s->programs.standingErrors()) errors.push_back(s->id + ": " + e);
    }
    return errors;
}

std::vector<std::string> Runtime::portabilityWarnings() const {
    std::vector<std::string> warnings;
    for (auto& s : slots_)
        for (auto& w : s->programs.portabilityWarnings()) warnings.push_back(s->id + ": " + w);
    return warnings;
}

void Runtime::setExternalError(const std::string& key, const std::string& message) {
    if (message.empty()) externalErrors_.erase(key);
    else externalErrors_[key] = message;
}

int Runtime::reloadShaders(const std::vector<fs::path>& changed) {
    int rebuilt = 0;
    for (auto& slot : slots_) {
        const int n = slot->programs.reload(*shaders_, changed);
        if (n > 0) slot->error.clear();
        rebuilt += n;
    }
    return rebuilt;
}

}  // namespace kiln::run
