#include "run/pass_context.hpp"

#include <algorithm>
#include <cctype>

#include "kiln/log.hpp"

namespace kiln::run {

namespace {

std::string upper(std::string s) {
    for (auto& c : s) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
    return s;
}

}  // namespace

const TextureRef& HostPassContext::input(std::string_view name) const {
    const graph::Binding* b = planned_.binding(name);
    if (!b) return missing("input", name);
    if (b->bound()) {
        const PassSlot& producer = *shared_.slots[static_cast<size_t>(b->producer)];
        auto it = producer.textures.find(b->output);
        return it != producer.textures.end() ? it->second.ref : missing("input", name);
    }
    for (auto& in : planned_.decl.inputs)
        if (in.name == name) return shared_.fallbacks.get(in.kind, in.fallback);
    return missing("input", name);
}

bool HostPassContext::isBound(std::string_view name) const {
    const graph::Binding* b = planned_.binding(name);
    return b && b->bound();
}

bool HostPassContext::isRead(std::string_view name) const {
    if (planned_.outputIndex(name) < 0) {
        missing("output", name);
        return true;
    }
    return shared_.readEverything || planned_.outputIsRead(name);
}

const ParamValue& HostPassContext::param(std::string_view name) const {
    if (const ParamValue* v = planned_.params.find(name)) return *v;
    static const ParamValue none = 0.0f;
    failed_ = true;
    slot_.error = str("unknown parameter \"", name, "\" (not declared)");
    return none;
}

GLuint HostPassContext::program(const ProgramDesc& descIn) {
    ProgramDesc desc = descIn;
    for (auto& in : planned_.decl.inputs)
        desc.defines.emplace_back("KILN_HAS_" + upper(in.name), isBound(in.name) ? "1" : "0");
    if (desc.debugName.empty() && !desc.stages.empty()) desc.debugName = slot_.id + ":" + desc.stages.back();
    std::string error;
    const GLuint id = slot_.programs.get(shared_.shaders, desc, error);
    if (!id) {
        fail(error);
        slot_.loggedError = slot_.error;  // the program cache printed it when the build failed
    }
    return id;
}

GLuint HostPassContext::framebuffer(std::initializer_list<std::string_view> colors, std::string_view depth, int mip) {
    std::string key;
    for (auto c : colors) key += std::string(c) + ",";
    key += "|" + std::string(depth) + "@" + std::to_string(mip);
    auto it = slot_.framebuffers.find(key);
    if (it == slot_.framebuffers.end()) {
        gl::FramebufferHandle handle = gl::createFramebuffer();
        const GLuint fbo = handle.id();
        std::vector<GLenum> drawBuffers;
        GLenum attachment = GL_COLOR_ATTACHMENT0;
        for (auto c : colors) {
            glNamedFramebufferTexture(fbo, attachment, ownTexture(c).id, mip);
            drawBuffers.push_back(attachment++);
        }
        if (!depth.empty()) glNamedFramebufferTexture(fbo, GL_DEPTH_ATTACHMENT, ownTexture(depth).id, mip);
        if (drawBuffers.empty()) glNamedFramebufferDrawBuffer(fbo, GL_NONE);
        else glNamedFramebufferDrawBuffers(fbo, static_cast<GLsizei>(drawBuffers.size()), drawBuffers.data());
        const GLenum status = glCheckNamedFramebufferStatus(fbo, GL_FRAMEBUFFER);
        if (status != GL_FRAMEBUFFER_COMPLETE) {
            fail(str("framebuffer ", key, " incomplete (0x", std::hex, status, ")"));
            return 0;
        }
        gl::label(GL_FRAMEBUFFER, fbo, slot_.id + ".fbo[" + key + "]");
        it = slot_.framebuffers.emplace(key, std::move(handle)).first;
    }
    // Bound, with the viewport over the first attachment's mip level.
    const TextureRef& first = colors.size() ? ownTexture(*colors.begin()) : ownTexture(depth);
    glBindFramebuffer(GL_FRAMEBUFFER, it->second.id());
    glViewport(0, 0, std::max(1, first.width >> mip), std::max(1, first.height >> mip));
    return it->second.id();
}

void HostPassContext::drawFullscreenTriangle() {
    glBindVertexArray(shared_.emptyVao);
    glDrawArrays(GL_TRIANGLES, 0, 3);
}

void HostPassContext::fail(std::string_view message) {
    failed_ = true;
    slot_.error = std::string(message);
}

void HostPassContext::keepRunning(int frames, std::string_view reason) {
    if (settling_) return;  // the frames a change started are not extended by themselves
    slot_.settlingFrames = std::max(frames, 0);
    slot_.settlingReason = std::string(reason);
}

const TextureRef& HostPassContext::texture(std::string_view name, bool internal) const {
    auto it = slot_.textures.find(name);
    if (it == slot_.textures.end() || it->second.internal != internal)
        return missing(internal ? "internal texture" : "output", name);
    return it->second.ref;
}

const TextureRef& HostPassContext::ownTexture(std::string_view name) const {
    auto it = slot_.textures.find(name);
    return it == slot_.textures.end() ? missing("texture", name) : it->second.ref;
}

const TextureRef& HostPassContext::missing(const char* what, std::string_view name) const {
    static const TextureRef none{};
    failed_ = true;
    slot_.error = str("asked for ", what, " \"", name, "\", which it does not declare");
    return none;
}

}  // namespace kiln::run
