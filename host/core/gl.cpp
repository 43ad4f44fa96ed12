#include "kiln/gl.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>

#include "kiln/log.hpp"

namespace kiln::gl {

int loadGL(GLADloadfunc getProc) {
    int version = gladLoadGL(getProc);
    if (!version) return 0;
    return GLAD_VERSION_MAJOR(version) * 10 + GLAD_VERSION_MINOR(version);
}

namespace {
std::atomic<uint64_t> gErrors{0};

void GLAPIENTRY onDebugMessage(GLenum source, GLenum type, GLuint id, GLenum severity, GLsizei,
                               const GLchar* message, const void*) {
    // Compile errors come back through buildProgram(), mapped to file:line.
    if (source == GL_DEBUG_SOURCE_SHADER_COMPILER) return;
    if (severity == GL_DEBUG_SEVERITY_NOTIFICATION) return;
    if (type == GL_DEBUG_TYPE_PUSH_GROUP || type == GL_DEBUG_TYPE_POP_GROUP) return;
    const bool isError = type == GL_DEBUG_TYPE_ERROR || severity == GL_DEBUG_SEVERITY_HIGH;
    if (type == GL_DEBUG_TYPE_ERROR) ++gErrors;
    if (isError)
        log::error("GL [", id, "] ", message);
    else
        log::warn("GL [", id, "] ", message);
}
}  // namespace

uint64_t debugErrorCount() { return gErrors.load(); }

void installDebugCallback() {
    if (!glDebugMessageCallback) return;
    glEnable(GL_DEBUG_OUTPUT);
    glEnable(GL_DEBUG_OUTPUT_SYNCHRONOUS);
    glDebugMessageCallback(onDebugMessage, nullptr);
}

void label(GLenum identifier, GLuint name, std::string_view text) {
    if (!glObjectLabel || name == 0) return;
    glObjectLabel(identifier, name, static_cast<GLsizei>(text.size()), text.data());
}

DebugGroup::DebugGroup(std::string_view name) {
    if (glPushDebugGroup)
        glPushDebugGroup(GL_DEBUG_SOURCE_APPLICATION, 0, static_cast<GLsizei>(name.size()), name.data());
}
DebugGroup::~DebugGroup() {
    if (glPopDebugGroup) glPopDebugGroup();
}

namespace {
// The unit a sampler or image uniform was given by layout(binding = N); -1 if inactive.
GLint unitOf(GLuint program, const char* name) {
    const GLint location = glGetUniformLocation(program, name);
    if (location < 0) return -1;
    GLint unit = -1;
    glGetUniformiv(program, location, &unit);
    return unit;
}
}  // namespace

bool bindTexture(GLuint program, const char* sampler, GLuint texture) {
    const GLint unit = unitOf(program, sampler);
    if (unit >= 0) glBindTextureUnit(GLuint(unit), texture);
    return unit >= 0;
}

bool bindSamplerObject(GLuint program, const char* sampler, GLuint samplerObject) {
    const GLint unit = unitOf(program, sampler);
    if (unit >= 0) glBindSampler(GLuint(unit), samplerObject);
    return unit >= 0;
}

bool bindImage(GLuint program, const char* image, GLuint texture, GLint level, bool layered, GLenum access,
               GLenum format) {
    const GLint unit = unitOf(program, image);
    if (unit >= 0) glBindImageTexture(GLuint(unit), texture, level, layered ? GL_TRUE : GL_FALSE, 0, access, format);
    return unit >= 0;
}

bool bindStorageBuffer(GLuint program, const char* block, GLuint buffer) {
    const GLuint index = glGetProgramResourceIndex(program, GL_SHADER_STORAGE_BLOCK, block);
    if (index == GL_INVALID_INDEX) return false;
    const GLenum property = GL_BUFFER_BINDING;
    GLint binding = -1;
    glGetProgramResourceiv(program, GL_SHADER_STORAGE_BLOCK, index, 1, &property, 1, nullptr, &binding);
    if (binding >= 0) glBindBufferBase(GL_SHADER_STORAGE_BUFFER, GLuint(binding), buffer);
    return binding >= 0;
}

namespace detail {
void deleteTexture(GLuint id) { glDeleteTextures(1, &id); }
void deleteBuffer(GLuint id) { glDeleteBuffers(1, &id); }
void deleteFramebuffer(GLuint id) { glDeleteFramebuffers(1, &id); }
void deleteVertexArray(GLuint id) { glDeleteVertexArrays(1, &id); }
void deleteProgram(GLuint id) { glDeleteProgram(id); }
void deleteShader(GLuint id) { glDeleteShader(id); }
void deleteQuery(GLuint id) { glDeleteQueries(1, &id); }
void deleteSampler(GLuint id) { glDeleteSamplers(1, &id); }
}  // namespace detail

FramebufferHandle createFramebuffer() {
    GLuint id = 0;
    glCreateFramebuffers(1, &id);
    return FramebufferHandle(id);
}
FramebufferHandle createDepthFramebuffer(GLuint depthTexture) {
    FramebufferHandle fbo = createFramebuffer();
    glNamedFramebufferTexture(fbo.id(), GL_DEPTH_ATTACHMENT, depthTexture, 0);
    glNamedFramebufferDrawBuffer(fbo.id(), GL_NONE);
    if (glCheckNamedFramebufferStatus(fbo.id(), GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) fbo.reset();
    return fbo;
}
VertexArrayHandle createVertexArray() {
    GLuint id = 0;
    glCreateVertexArrays(1, &id);
    return VertexArrayHandle(id);
}
SamplerHandle createSampler() {
    GLuint id = 0;
    glCreateSamplers(1, &id);
    return SamplerHandle(id);
}

int Texture::fullMipCount(int w, int h, int d) {
    int m = std::max({w, h, d, 1});
    return 1 + static_cast<int>(std::floor(std::log2(static_cast<double>(m))));
}

Texture Texture::create(GLenum target, GLenum internalFormat, int w, int h, int d, int levels,
                        std::string_view debugName) {
    Texture t;
    GLuint id = 0;
    glCreateTextures(target, 1, &id);
    t.handle_ = Handle<detail::deleteTexture>(id);
    t.target_ = target;
    t.format_ = internalFormat;
    t.w_ = w;
    t.h_ = h;
    t.d_ = target == GL_TEXTURE_3D ? d : 1;
    t.levels_ = std::max(1, levels);
    if (target == GL_TEXTURE_3D)
        glTextureStorage3D(id, t.levels_, internalFormat, w, h, d);
    else
        glTextureStorage2D(id, t.levels_, internalFormat, w, h);

    const bool isInteger = isIntegerFormat(internalFormat);
    const bool isDepth = isDepthFormat(internalFormat);
    const GLint minFilter = isInteger ? GL_NEAREST : (t.levels_ > 1 ? GL_LINEAR_MIPMAP_LINEAR : GL_LINEAR);
    glTextureParameteri(id, GL_TEXTURE_MIN_FILTER, minFilter);
    glTextureParameteri(id, GL_TEXTURE_MAG_FILTER, isInteger ? GL_NEAREST : GL_LINEAR);
    glTextureParameteri(id, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTextureParameteri(id, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    glTextureParameteri(id, GL_TEXTURE_WRAP_R, GL_CLAMP_TO_EDGE);
    if (isDepth) glTextureParameteri(id, GL_TEXTURE_COMPARE_MODE, GL_NONE);
    label(GL_TEXTURE, id, debugName);
    return t;
}

Buffer Buffer::create(GLsizeiptr bytes, const void* data, GLbitfield flags, std::string_view debugName) {
    Buffer b;
    GLuint id = 0;
    glCreateBuffers(1, &id);
    b.handle_ = BufferHandle(id);
    b.size_ = bytes;
    glNamedBufferStorage(id, std::max<GLsizeiptr>(bytes, 1), data, flags);
    label(GL_BUFFER, id, debugName);
    return b;
}

void GpuTimer::begin() {
    if (!starts_[0]) {
        for (int i = 0; i < kRing; ++i) {
            GLuint ids[2] = {};
            glCreateQueries(GL_TIMESTAMP, 2, ids);
            starts_[i] = QueryHandle(ids[0]);
            ends_[i] = QueryHandle(ids[1]);
        }
    }
    // A slot whose result has not arrived yet is skipped this frame rather than
    // waited on: the measurement is lost, the CPU never stalls.
    if (pending_[next_]) return;
    glQueryCounter(starts_[next_].id(), GL_TIMESTAMP);
    open_ = true;
}

void GpuTimer::end() {
    if (!open_) return;
    glQueryCounter(ends_[next_].id(), GL_TIMESTAMP);
    pending_[next_] = true;
    next_ = (next_ + 1) % kRing;
    open_ = false;
}

bool GpuTimer::poll(int slot, double& ms) {
    if (!pending_[slot]) return false;
    GLint available = 0;
    glGetQueryObjectiv(ends_[slot].id(), GL_QUERY_RESULT_AVAILABLE, &available);
    if (!available) return false;
    GLuint64 t0 = 0, t1 = 0;
    glGetQueryObjectui64v(starts_[slot].id(), GL_QUERY_RESULT, &t0);
    glGetQueryObjectui64v(ends_[slot].id(), GL_QUERY_RESULT, &t1);
    pending_[slot] = false;
    ms = t1 >= t0 ? static_cast<double>(t1 - t0) * 1e-6 : 0.0;
    return true;
}

const char* formatName(GLenum f) {
    switch (f) {
        case GL_RGBA8: return "GL_RGBA8";
        case GL_RGBA16F: return "GL_RGBA16F";
        case GL_RGBA32F: return "GL_RGBA32F";
        case GL_RG16F: return "GL_RG16F";
        case GL_R16F: return "GL_R16F";
        case GL_R32F: return "GL_R32F";
        case GL_R11F_G11F_B10F: return "GL_R11F_G11F_B10F";
        case GL_R32UI: return "GL_R32UI";
        case GL_DEPTH_COMPONENT32F: return "GL_DEPTH_COMPONENT32F";
        case GL_DEPTH_COMPONENT24: return "GL_DEPTH_COMPONENT24";
        default: return "GL_(unknown format)";
    }
}

}  // namespace kiln::gl
