#include "app/runtime.hpp"

#include <algorithm>
#include <cctype>
#include <fstream>
#include <iomanip>
#include <numeric>
#include <sstream>

#include "kiln/image_io.hpp"
#include "kiln/log.hpp"

namespace fs = std::filesystem;

namespace kiln::app {

namespace {

GLenum glFormat(Format f) {
    switch (f) {
        case Format::RGBA8: return GL_RGBA8;
        case Format::RGBA16F: return GL_RGBA16F;
        case Format::RGBA32F: return GL_RGBA32F;
        case Format::RG16F: return GL_RG16F;
        case Format::R16F: return GL_R16F;
        case Format::R32F: return GL_R32F;
        case Format::R11G11B10F: return GL_R11F_G11F_B10F;
        case Format::R32UI: return GL_R32UI;
        case Format::Depth32F: return GL_DEPTH_COMPONENT32F;
        case Format::Depth24: return GL_DEPTH_COMPONENT24;
    }
    return GL_RGBA8;
}

bool isFloatFormat(GLenum f) { return f != GL_RGBA8 && f != GL_R32UI; }

double median(std::deque<double> v) {
    if (v.empty()) return -1.0;
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
}
double mean(const std::deque<double>& v, size_t lastN) {
    if (v.empty()) return -1.0;
    size_t n = std::min(lastN, v.size());
    return std::accumulate(v.end() - static_cast<long>(n), v.end(), 0.0) / static_cast<double>(n);
}

std::string upper(std::string s) {
    for (auto& c : s) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
    return s;
}

constexpr size_t kMaxSamples = 2000;
constexpr size_t kRollingWindow = 30;

}  // namespace

// The PassContext a pass sees during execute(): resources by declared name, its
// parameters, the scene and the helpers. One per pass per frame, on the stack.
class Runtime::Context final : public PassContext {
public:
    Context(Runtime& rt, PassSlot& slot, const graph::PlannedPass& planned, const SceneView& view,
            const FrameInfo& frame)
        : rt_(rt), slot_(slot), planned_(planned), view_(view), frame_(frame) {}

    const TextureRef& input(std::string_view name) const override {
        const graph::Binding* b = planned_.binding(name);
        if (!b) return missing("input", name);
        if (b->bound()) {
            const PassSlot& producer = *rt_.slots_[static_cast<size_t>(b->producer)];
            auto it = producer.textures.find(b->output);
            if (it != producer.textures.end()) return it->second.ref;
            return missing("input", name);
        }
        for (auto& in : planned_.decl.inputs)
            if (in.name == name) return rt_.fallback(in.kind, in.fallback);
        return missing("input", name);
    }
    bool isBound(std::string_view name) const override {
        const graph::Binding* b = planned_.binding(name);
        return b && b->bound();
    }
    const TextureRef& output(std::string_view name) const override { return texture(name, false); }
    const TextureRef& internal(std::string_view name) const override { return texture(name, true); }
    const ParamValue& param(std::string_view name) const override {
        if (const ParamValue* v = planned_.params.find(name)) return *v;
        static const ParamValue none = 0.0f;
        const_cast<Context*>(this)->fail(str("unknown parameter \"", name, "\" (not declared)"));
        return none;
    }
    const SceneView& scene() const override { return view_; }
    const FrameInfo& frame() const override { return frame_; }

    GLuint program(const ProgramDesc& descIn) override {
        ProgramDesc desc = descIn;
        for (auto& in : planned_.decl.inputs)
            desc.defines.emplace_back("KILN_HAS_" + upper(in.name), isBound(in.name) ? "1" : "0");
        std::string key;
        for (auto& s : desc.stages) key += s + ";";
        for (auto& [k, v] : desc.defines) key += k + "=" + v + ";";
        auto it = slot_.programs.find(key);
        if (it == slot_.programs.end()) {
            if (desc.debugName.empty()) desc.debugName = slot_.id + ":" + desc.stages.back();
            ProgramBuild build = buildProgram(*rt_.shaders_, desc);
            ProgramEntry entry;
            entry.desc = desc;
            entry.dependencies = build.dependencies;
            ++slot_.programGeneration;
            if (build.ok()) {
                entry.program = std::move(build.program);
            } else {
                entry.error = build.errorText();
                if (!entry.error.empty() && entry.error.back() == '\n') entry.error.pop_back();
                log::error(entry.error);
            }
            it = slot_.programs.emplace(key, std::move(entry)).first;
        }
        if (!it->second.program) {
            failed_ = true;
            slot_.error = it->second.error;
            return 0;
        }
        return it->second.program.id();
    }

    GLuint framebuffer(std::initializer_list<std::string_view> colors, std::string_view depth, int mip) override {
        std::string key;
        for (auto c : colors) key += std::string(c) + ",";
        key += "|" + std::string(depth) + "@" + std::to_string(mip);
        auto it = slot_.framebuffers.find(key);
        if (it == slot_.framebuffers.end()) {
            GLuint fbo = 0;
            glCreateFramebuffers(1, &fbo);
            gl::FramebufferHandle handle(fbo);
            std::vector<GLenum> drawBuffers;
            GLenum attachment = GL_COLOR_ATTACHMENT0;
            for (auto c : colors) {
                glNamedFramebufferTexture(fbo, attachment, ownTexture(c).id, mip);
                drawBuffers.push_back(attachment++);
            }
            if (!depth.empty()) glNamedFramebufferTexture(fbo, GL_DEPTH_ATTACHMENT, ownTexture(depth).id, mip);
            glNamedFramebufferDrawBuffers(fbo, static_cast<GLsizei>(drawBuffers.size()),
                                          drawBuffers.empty() ? nullptr : drawBuffers.data());
            if (drawBuffers.empty()) glNamedFramebufferDrawBuffer(fbo, GL_NONE);
            GLenum status = glCheckNamedFramebufferStatus(fbo, GL_FRAMEBUFFER);
            if (status != GL_FRAMEBUFFER_COMPLETE) {
                fail(str("framebuffer ", key, " incomplete (0x", std::hex, status, ")"));
                return 0;
            }
            gl::label(GL_FRAMEBUFFER, fbo, slot_.id + ".fbo[" + key + "]");
            it = slot_.framebuffers.emplace(key, std::move(handle)).first;
        }
        // Bind and size the viewport to the first attachment, the common case.
        const TextureRef& first = colors.size() ? ownTexture(*colors.begin()) : ownTexture(depth);
        glBindFramebuffer(GL_FRAMEBUFFER, it->second.id());
        glViewport(0, 0, std::max(1, first.width >> mip), std::max(1, first.height >> mip));
        return it->second.id();
    }

    void drawFullscreenTriangle() override {
        glBindVertexArray(rt_.emptyVao_.id());
        glDrawArrays(GL_TRIANGLES, 0, 3);
    }
    void drawScene(const DrawFilter& filter) override { rt_.scene_.draw(filter); }
    void nothingToDo(std::string_view reason) override { nothing_ = std::string(reason); }
    void fail(std::string_view message) override {
        failed_ = true;
        slot_.error = std::string(message);
    }

    bool failed() const { return failed_; }
    const std::optional<std::string>& nothing() const { return nothing_; }

private:
    const TextureRef& texture(std::string_view name, bool internal) const {
        auto it = slot_.textures.find(name);
        if (it == slot_.textures.end() || it->second.internal != internal)
            return missing(internal ? "internal texture" : "output", name);
        return it->second.ref;
    }
    const TextureRef& ownTexture(std::string_view name) const {
        auto it = slot_.textures.find(name);
        return it == slot_.textures.end() ? missing("texture", name) : it->second.ref;
    }
    const TextureRef& missing(const char* what, std::string_view name) const {
        static const TextureRef none{};
        const_cast<Context*>(this)->fail(str("asked for ", what, " \"", name, "\", which it does not declare"));
        return none;
    }

    Runtime& rt_;
    PassSlot& slot_;
    const graph::PlannedPass& planned_;
    const SceneView& view_;
    const FrameInfo& frame_;
    bool failed_ = false;
    std::optional<std::string> nothing_;
};

Runtime::Runtime() = default;
Runtime::~Runtime() {
    // Pass objects go before the modules whose code destroys them (PassPtr keeps its
    // module alive), and before the GL objects they might reference.
    slots_.clear();
    modules_.clear();
}

bool Runtime::init(const RuntimeOptions& options, std::string& error) {
    options_ = options;
    loader_ = std::make_unique<ModuleLoader>(options.moduleDirs);
    shaders_ = std::make_unique<ShaderLibrary>(options.shaderRoots);
    if (shaders_->resolve("common/frame.glsl").empty()) {
        error = "shader root without common/frame.glsl; looked in: ";
        for (auto& r : options.shaderRoots) error += r.string() + " ";
        return false;
    }
    frameUniforms_ = gl::Buffer::create(sizeof(GpuFrame), nullptr, GL_DYNAMIC_STORAGE_BIT, "kiln.frame");
    GLuint vao = 0;
    glCreateVertexArrays(1, &vao);
    emptyVao_ = gl::VertexArrayHandle(vao);

    auto make2d = [](GLenum fmt, const char* name, const float* rgba) {
        gl::Texture t = gl::Texture::create(GL_TEXTURE_2D, fmt, 1, 1, 1, 1, name);
        if (fmt == GL_DEPTH_COMPONENT32F)
            glClearTexImage(t.id(), 0, GL_DEPTH_COMPONENT, GL_FLOAT, rgba);
        else
            glClearTexImage(t.id(), 0, GL_RGBA, GL_FLOAT, rgba);
        return t;
    };
    const float black[4] = {0, 0, 0, 0}, white[4] = {1, 1, 1, 1}, flat[4] = {0, 0, 1, 0}, far[1] = {1.0f};
    fallbacks_.black = make2d(GL_RGBA16F, "fallback.black", black);
    fallbacks_.white = make2d(GL_RGBA16F, "fallback.white", white);
    fallbacks_.flatNormal = make2d(GL_RGBA16F, "fallback.flat_normal", flat);
    fallbacks_.farDepth = make2d(GL_DEPTH_COMPONENT32F, "fallback.far_depth", far);
    fallbacks_.black3d = gl::Texture::create(GL_TEXTURE_3D, GL_RGBA16F, 1, 1, 1, 1, "fallback.black3d");
    glClearTexImage(fallbacks_.black3d.id(), 0, GL_RGBA, GL_FLOAT, black);
    gl::Texture* all[5] = {&fallbacks_.black, &fallbacks_.white, &fallbacks_.flatNormal, &fallbacks_.farDepth,
                           &fallbacks_.black3d};
    for (int i = 0; i < 5; ++i)
        fallbacks_.refs[i] = {all[i]->id(), all[i]->target(), all[i]->internalFormat(), 1, 1, 1, 1, false};
    return true;
}

const TextureRef& Runtime::fallback(TextureKind kind, Fallback fb) const {
    if (kind == TextureKind::Color3D) return fallbacks_.refs[4];
    if (kind == TextureKind::Depth2D) return fallbacks_.refs[3];
    switch (fb) {
        case Fallback::White: return fallbacks_.refs[1];
        case Fallback::FlatNormal: return fallbacks_.refs[2];
        case Fallback::FarDepth: return fallbacks_.refs[3];
        case Fallback::Black: break;
    }
    return fallbacks_.refs[0];
}

graph::Result<PassDeclaration> Runtime::declarationOf(const std::string& module) {
    auto it = modules_.find(module);
    if (it != modules_.end()) return it->second.decl;
    std::string error;
    auto library = loader_->load(module, error);
    if (!library) return graph::Result<PassDeclaration>::failure(error);
    PassPtr probe = ModuleLoader::create(library, error);
    if (!probe) return graph::Result<PassDeclaration>::failure(error);
    PassDeclaration decl;
    try {
        decl = probe->declare();
    } catch (const std::exception& e) {
        return graph::Result<PassDeclaration>::failure(library->sourcePath().string() + ": declare() threw: " + e.what());
    }
    modules_[module] = {library, decl};
    return decl;
}

bool Runtime::loadPipeline(const fs::path& file, std::string& errors) {
    std::ifstream in(file, std::ios::binary);
    if (!in) {
        errors = file.string() + ": cannot read pipeline file";
        return false;
    }
    std::stringstream ss;
    ss << in.rdbuf();
    return loadPipelineText(ss.str(), file.string(), errors);
}

bool Runtime::loadPipelineText(const std::string& text, const std::string& displayName, std::string& errors) {
    graph::CompileOptions opt;
    opt.resolve = [this](const std::string& m) { return declarationOf(m); };
    opt.availableModules = loader_->available();
    opt.requested = requested_;
    auto result = graph::compileText(text, displayName, opt);
    if (!result) {
        errors = result.errorText();
        return false;
    }
    for (auto& w : result->warnings) log::warn(w.str());
    pipelineText_ = text;
    pipelineFile_ = displayName;
    adoptPlan(std::move(*result));
    return true;
}

void Runtime::setRequested(std::vector<std::string> requested) {
    if (requested == requested_) return;
    requested_ = std::move(requested);
    recompilePlan();
}

void Runtime::recompilePlan() {
    if (pipelineText_.empty()) return;
    std::string errors;
    if (!loadPipelineText(pipelineText_, pipelineFile_, errors)) log::error(errors);
}

void Runtime::adoptPlan(graph::Plan plan) {
    // A pass whose id and signature (module, parameters, inputs) are unchanged keeps
    // everything: pass object, textures, programs, skip state. One whose parameters or
    // inputs changed keeps its textures where their shape is the same (allocateTextures
    // decides) and its compiled programs, but gets a fresh pass object and runs again.
    // Anything else starts fresh.
    std::map<std::string, std::unique_ptr<PassSlot>> old;
    for (auto& s : slots_) old[s->id] = std::move(s);
    std::vector<std::unique_ptr<PassSlot>> next;
    int kept = 0, rerun = 0;
    for (auto& planned : plan.passes) {
        auto it = old.find(planned.id);
        std::unique_ptr<PassSlot> slot;
        if (it != old.end() && it->second->module == planned.module) {
            slot = std::move(it->second);
            old.erase(it);
            if (slot->signature == planned.signatureHash) {
                ++kept;
            } else {
                slot->pass.reset();  // its cached decisions were made for other parameters
                slot->signature = planned.signatureHash;
                slot->error.clear();
                ++rerun;
            }
        } else {
            slot = std::make_unique<PassSlot>();
            slot->id = planned.id;
            slot->module = planned.module;
            slot->signature = planned.signatureHash;
        }
        if (planned.state == graph::PassState::Disabled) {
            slot->textures.clear();
            slot->framebuffers.clear();
        } else if (!slot->pass) {
            auto& info = modules_.at(planned.module);
            std::string error;
            slot->library = info.library;
            slot->pass = ModuleLoader::create(info.library, error);
            if (!slot->pass) slot->error = error;
            slot->lastRunKey.reset();
        }
        next.push_back(std::move(slot));
    }
    slots_ = std::move(next);
    plan_ = std::move(plan);
    for (size_t i = 0; i < slots_.size(); ++i)
        if (plan_->passes[i].state != graph::PassState::Disabled) allocateTextures(*slots_[i], plan_->passes[i]);
    log::info("pipeline ", plan_->fileName, ": ", plan_->runOrder().size(), " of ", plan_->passes.size(),
              " passes run; ", kept, " unchanged, ", rerun, " changed in parameters or inputs");
}

void Runtime::allocateTextures(PassSlot& slot, const graph::PlannedPass& planned) {
    auto want = [&](const TextureDecl& d, bool internal) {
        graph::Extent e = graph::resolveSize(d, options_.width, options_.height, planned.params);
        const GLenum target = d.kind == TextureKind::Color3D ? GL_TEXTURE_3D : GL_TEXTURE_2D;
        const GLenum format = glFormat(d.format);
        const int levels = d.mips == kFullMipChain ? gl::Texture::fullMipCount(e.w, e.h, target == GL_TEXTURE_3D ? e.d : 1)
                                                   : std::max(1, d.mips);
        auto it = slot.textures.find(d.name);
        if (it != slot.textures.end()) {
            const gl::Texture& t = it->second.texture;
            if (t.target() == target && t.internalFormat() == format && t.width() == e.w && t.height() == e.h &&
                (target != GL_TEXTURE_3D || t.depth() == e.d) && t.levels() == levels && it->second.internal == internal)
                return;  // same shape: keep it (and its contents)
        }
        TextureSlot ts;
        ts.decl = d;
        ts.internal = internal;
        ts.texture = gl::Texture::create(target, format, e.w, e.h, e.d, levels, slot.id + "." + d.name);
        // Fresh textures start at zero, so a pass that skips its first run (nothing to
        // do) leaves defined contents behind.
        for (int l = 0; l < levels; ++l) {
            if (format == GL_DEPTH_COMPONENT32F || format == GL_DEPTH_COMPONENT24) {
                const float one = 1.0f;
                glClearTexImage(ts.texture.id(), l, GL_DEPTH_COMPONENT, GL_FLOAT, &one);
            } else if (format == GL_R32UI) {
                glClearTexImage(ts.texture.id(), l, GL_RED_INTEGER, GL_UNSIGNED_INT, nullptr);
            } else {
                glClearTexImage(ts.texture.id(), l, GL_RGBA, GL_FLOAT, nullptr);
            }
        }
        ts.ref = {ts.texture.id(), target, format, ts.texture.width(), ts.texture.height(), ts.texture.depth(), levels, true};
        ts.version = ++versionCounter_;
        slot.textures[d.name] = std::move(ts);
        slot.framebuffers.clear();
        slot.lastRunKey.reset();
    };
    for (auto& d : planned.decl.outputs) want(d, false);
    for (auto& d : planned.decl.internals) want(d, true);
    // Textures the declaration no longer has (a reloaded module renamed one) go.
    for (auto it = slot.textures.begin(); it != slot.textures.end();) {
        if (!planned.texture(it->first)) {
            it = slot.textures.erase(it);
            slot.framebuffers.clear();
        } else {
            ++it;
        }
    }
}

void Runtime::resize(int width, int height) {
    if (width == options_.width && height == options_.height) return;
    options_.width = std::max(1, width);
    options_.height = std::max(1, height);
    if (!plan_) return;
    for (size_t i = 0; i < slots_.size(); ++i)
        if (plan_->passes[i].state != graph::PassState::Disabled) allocateTextures(*slots_[i], plan_->passes[i]);
}

std::vector<uint64_t> Runtime::runKey(const graph::PlannedPass& planned, const PassSlot& slot,
                                      const SceneView& view) const {
    // Everything whose change must make the pass run again: each input's version
    // (0 for a fallback), each scene category it reads, and the output size.
    std::vector<uint64_t> key;
    for (auto& b : planned.bindings) {
        if (!b.bound()) {
            key.push_back(0);
            continue;
        }
        const PassSlot& producer = *slots_[static_cast<size_t>(b.producer)];
        auto it = producer.textures.find(b.output);
        key.push_back(it == producer.textures.end() ? 0 : it->second.version);
    }
    for (int i = 0; i < 6; ++i)
        key.push_back((planned.decl.reads & (1u << i)) ? view.versions[i] : 0);
    key.push_back(static_cast<uint64_t>(options_.width) << 32 | static_cast<uint32_t>(options_.height));
    key.push_back(slot.programGeneration);  // a newly (re)built program runs the pass again
    return key;
}

void Runtime::renderFrame(const SceneView& view, const FrameInfo& frameIn) {
    FrameInfo frame = frameIn;
    frame.outputWidth = options_.width;
    frame.outputHeight = options_.height;
    scene_.upload();
    GpuFrame gpuFrame = view.frame;
    gpuFrame.outputSize = {float(options_.width), float(options_.height), 1.0f / float(options_.width),
                           1.0f / float(options_.height)};
    gpuFrame.time = {float(frame.time), float(frame.dt), float(frame.index), 0.0f};
    glNamedBufferSubData(frameUniforms_.id(), 0, sizeof(GpuFrame), &gpuFrame);
    collectGpuTimes();
    if (!plan_) return;

    for (size_t i = 0; i < slots_.size(); ++i) {
        PassSlot& slot = *slots_[i];
        const graph::PlannedPass& planned = plan_->passes[i];
        if (planned.state != graph::PassState::Run) {
            slot.lastState = graph::toString(planned.state);
            slot.lastWhy = planned.reason;
            continue;
        }
        if (!slot.pass) {
            slot.lastState = "error";
            slot.lastWhy = slot.error;
            continue;
        }
        auto key = runKey(planned, slot, view);
        if (!alwaysRun && !planned.decl.timeDependent && slot.lastRunKey && *slot.lastRunKey == key && slot.error.empty()) {
            slot.lastState = "skipped";
            slot.lastWhy = "inputs, parameters and scene unchanged";
            ++slot.skippedFrames;
            continue;
        }

        // A clean slate for every pass, so one pass's GL state never leaks into the next.
        glBindFramebuffer(GL_FRAMEBUFFER, 0);
        glViewport(0, 0, options_.width, options_.height);
        glDisable(GL_DEPTH_TEST);
        glDisable(GL_BLEND);
        glDisable(GL_CULL_FACE);
        glDepthMask(GL_TRUE);
        glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
        glBindBufferBase(GL_UNIFORM_BUFFER, kFrameBinding, frameUniforms_.id());

        slot.error.clear();
        Context ctx(*this, slot, planned, view, frame);
        const auto cpuStart = std::chrono::steady_clock::now();
        {
            gl::DebugGroup group(slot.id);
            slot.timer.begin();
            try {
                slot.pass->execute(ctx);
            } catch (const std::exception& e) {
                ctx.fail(str("execute() threw: ", e.what()));
            }
            slot.timer.end();
        }
        const double cpuMs = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - cpuStart).count();
        glUseProgram(0);
        glBindVertexArray(0);

        slot.cpuSamples.push_back(cpuMs);
        if (slot.cpuSamples.size() > kMaxSamples) slot.cpuSamples.pop_front();

        if (ctx.failed()) {
            slot.lastState = "error";
            slot.lastWhy = slot.error;
            slot.lastRunKey.reset();
            continue;
        }
        ++slot.ranFrames;
        slot.lastRunKey = runKey(planned, slot, view);
        if (ctx.nothing()) {
            slot.lastState = "nothing to do";
            slot.lastWhy = *ctx.nothing();
            continue;
        }
        slot.lastState = "ran";
        slot.lastWhy.clear();
        for (auto& [name, tex] : slot.textures) tex.version = ++versionCounter_;
    }
}

void Runtime::collectGpuTimes() {
    for (auto& s : slots_) {
        s->timer.collect(s->gpuSamples);
        while (s->gpuSamples.size() > kMaxSamples) s->gpuSamples.pop_front();
    }
}

void Runtime::resetTimings() {
    collectGpuTimes();
    for (auto& s : slots_) {
        s->gpuSamples.clear();
        s->cpuSamples.clear();
        s->ranFrames = s->skippedFrames = 0;
    }
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

std::vector<PassRow> Runtime::stats() const {
    std::vector<PassRow> rows;
    if (!plan_) return rows;
    for (size_t i = 0; i < slots_.size(); ++i) {
        const PassSlot& s = *slots_[i];
        PassRow r;
        r.id = s.id;
        r.module = s.module;
        r.state = s.lastState;
        r.why = s.lastWhy;
        r.gpuMs = mean(s.gpuSamples, kRollingWindow);
        r.cpuMs = s.cpuSamples.empty() ? 0.0 : mean(s.cpuSamples, kRollingWindow);
        r.gpuMedianMs = median(s.gpuSamples);
        r.cpuMedianMs = s.cpuSamples.empty() ? 0.0 : median(s.cpuSamples);
        r.ranFrames = s.ranFrames;
        r.skippedFrames = s.skippedFrames;
        rows.push_back(r);
    }
    return rows;
}

std::string Runtime::statsTable() const {
    std::ostringstream os;
    os << std::left << std::setw(14) << "pass" << std::setw(12) << "module" << std::setw(15) << "state" << std::right
       << std::setw(10) << "gpu ms" << std::setw(10) << "cpu ms" << std::setw(6) << "ran" << std::setw(8) << "skipped"
       << "  note\n";
    double gpuTotal = 0, cpuTotal = 0;
    for (auto& r : stats()) {
        auto ms = [](double v) {
            std::ostringstream s;
            if (v < 0) s << "-"; else s << std::fixed << std::setprecision(3) << v;
            return s.str();
        };
        os << std::left << std::setw(14) << r.id << std::setw(12) << r.module << std::setw(15) << r.state << std::right
           << std::setw(10) << ms(r.gpuMedianMs) << std::setw(10) << ms(r.ranFrames ? r.cpuMedianMs : -1)
           << std::setw(6) << r.ranFrames << std::setw(8) << r.skippedFrames << "  " << r.why << "\n";
        if (r.gpuMedianMs > 0) gpuTotal += r.gpuMedianMs;
        if (r.ranFrames) cpuTotal += r.cpuMedianMs;
    }
    os << std::left << std::setw(41) << "total (medians)" << std::right << std::setw(10) << std::fixed
       << std::setprecision(3) << gpuTotal << std::setw(10) << cpuTotal << "\n";
    return os.str();
}

std::vector<Runtime::TextureInfo> Runtime::textures() const {
    std::vector<TextureInfo> out;
    for (auto& s : slots_)
        for (auto& [name, t] : s->textures) out.push_back({s->id, name, t.internal, t.ref});
    return out;
}

std::vector<std::string> Runtime::activeErrors() const {
    std::vector<std::string> errors;
    for (auto& [key, message] : externalErrors_) errors.push_back(message);
    for (auto& s : slots_) {
        if (!s->error.empty()) errors.push_back(s->id + ": " + s->error);
        for (auto& [key, entry] : s->programs)
            if (!entry.error.empty() && entry.program)  // broken edit, last good program running
                errors.push_back(s->id + ": " + entry.error);
    }
    return errors;
}

void Runtime::setExternalError(const std::string& key, const std::string& message) {
    if (message.empty()) externalErrors_.erase(key);
    else externalErrors_[key] = message;
}

int Runtime::reloadShaders(const std::vector<fs::path>& changed) {
    int rebuilt = 0;
    for (auto& slot : slots_) {
        for (auto& [key, entry] : slot->programs) {
            bool affected = false;
            for (auto& dep : entry.dependencies)
                for (auto& c : changed) affected |= dep == c;
            if (!affected) continue;
            // Built aside; swapped in only if it compiles and links.
            ProgramBuild build = buildProgram(*shaders_, entry.desc);
            if (!build.dependencies.empty()) entry.dependencies = build.dependencies;
            if (build.ok()) {
                entry.program = std::move(build.program);
                entry.error.clear();
                slot->error.clear();
                ++slot->programGeneration;
                ++rebuilt;
            } else {
                entry.error = build.errorText();
                if (!entry.error.empty() && entry.error.back() == '\n') entry.error.pop_back();
                log::error(entry.error);
            }
        }
    }
    return rebuilt;
}

bool Runtime::reloadModule(const std::string& name, std::string& error) {
    auto library = loader_->load(name, error);
    if (!library) return false;
    PassPtr probe = ModuleLoader::create(library, error);
    if (!probe) return false;
    PassDeclaration decl;
    try {
        decl = probe->declare();
    } catch (const std::exception& e) {
        error = library->sourcePath().string() + ": declare() threw: " + e.what();
        return false;
    }
    probe.reset();
    // Validate the pipeline against the new declaration before touching anything.
    auto old = modules_.find(name) != modules_.end() ? std::optional<ModuleInfo>(modules_[name]) : std::nullopt;
    modules_[name] = {library, decl};
    std::string errors;
    if (!pipelineText_.empty() && !loadPipelineText(pipelineText_, pipelineFile_, errors)) {
        if (old) modules_[name] = *old;
        else modules_.erase(name);
        error = errors;
        return false;
    }
    old.reset();
    // Objects of the old library go first (their code lives there); their slots keep
    // textures and parameters, and get an object of the new library.
    for (size_t i = 0; i < slots_.size(); ++i) {
        auto& slot = *slots_[i];
        if (slot.module != name || plan_->passes[i].state == graph::PassState::Disabled) continue;
        slot.pass.reset();
        slot.library = library;
        slot.pass = ModuleLoader::create(library, error);
        if (!slot.pass) slot.error = error;
        slot.lastRunKey.reset();
    }
    return true;
}

bool Runtime::dump(const fs::path& dir, std::string& error) const {
    std::error_code ec;
    fs::create_directories(dir, ec);
    if (ec) {
        error = dir.string() + ": cannot create directory: " + ec.message();
        return false;
    }
    for (auto& t : textures()) {
        const TextureRef& r = t.ref;
        const int layer = r.target == GL_TEXTURE_3D ? r.depth / 2 : -1;
        FloatImage img = readTexture(r.id, r.target, r.format, r.width, r.height, 0, layer);
        const std::string base = (dir / (t.pass + "." + t.name)).string();
        if (!writePng(base + ".png", img, 4, error)) return false;
        if (isFloatFormat(r.format) && !writePfm(base + ".pfm", img, error)) return false;
    }
    return true;
}

}  // namespace kiln::app
