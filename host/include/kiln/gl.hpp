// kiln/gl.hpp — the GL loader and move-only owners for GL objects.
//
// Every GL call in the host and in pass modules goes through the one glad loader
// inside libkiln_core, so a module loaded (or reloaded) later needs no loader of its
// own. Owners are plain handles with one owner each: moving transfers the name,
// destruction deletes it. They must be destroyed while the context is current.
#pragma once

#include <glad/gl.h>

#include <string>
#include <string_view>
#include <utility>

namespace kiln::gl {

// Loads GL entry points through `getProc` (eglGetProcAddress, glfwGetProcAddress).
// Returns the GL version as major*10+minor, or 0 on failure.
int loadGL(GLADloadfunc getProc);

// Routes KHR_debug messages to the log (errors and performance warnings; the
// notification chatter is dropped).
void installDebugCallback();
// GL_DEBUG_TYPE_ERROR messages seen since start (the debug callback counts them): the
// tests and the soak run assert that Kiln causes none.
uint64_t debugErrorCount();

// Names a GL object for RenderDoc/apitrace (glObjectLabel), when KHR_debug is present.
void label(GLenum identifier, GLuint name, std::string_view text);

// A debug group for the scope: `DebugGroup g("gbuffer");`.
class DebugGroup {
public:
    explicit DebugGroup(std::string_view name);
    ~DebugGroup();
    DebugGroup(const DebugGroup&) = delete;
    DebugGroup& operator=(const DebugGroup&) = delete;
};

// Binding by the shader's own name for a resource: the unit is written once, in the
// shader's `layout(binding = N)`, and looked up here (glGetUniformiv gives a sampler's
// texture unit and an image's image unit; a block's GL_BUFFER_BINDING), so the C++ and
// the GLSL of a pass cannot drift apart. Each returns false, binding nothing, when
// `program` has no active resource of that name — one the compiler dropped because this
// variant does not use it; a misspelt name shows as a missing input in the image.
bool bindTexture(GLuint program, const char* sampler, GLuint texture);
bool bindSamplerObject(GLuint program, const char* sampler, GLuint samplerObject);
// `layered`: the whole of a 3D level (true) or one 2D image (false).
bool bindImage(GLuint program, const char* image, GLuint texture, GLint level, bool layered, GLenum access,
               GLenum format);
bool bindStorageBuffer(GLuint program, const char* block, GLuint buffer);

// One owner of a GL name. `Deleter` frees it.
template <void (*Deleter)(GLuint)>
class Handle {
public:
    Handle() = default;
    explicit Handle(GLuint id) : id_(id) {}
    ~Handle() { reset(); }
    Handle(Handle&& o) noexcept : id_(std::exchange(o.id_, 0)) {}
    Handle& operator=(Handle&& o) noexcept {
        if (this != &o) { reset(); id_ = std::exchange(o.id_, 0); }
        return *this;
    }
    Handle(const Handle&) = delete;
    Handle& operator=(const Handle&) = delete;

    GLuint id() const { return id_; }
    explicit operator bool() const { return id_ != 0; }
    void reset() { if (id_) Deleter(id_); id_ = 0; }
    GLuint release() { return std::exchange(id_, 0); }

private:
    GLuint id_ = 0;
};

namespace detail {
void deleteTexture(GLuint);
void deleteBuffer(GLuint);
void deleteFramebuffer(GLuint);
void deleteVertexArray(GLuint);
void deleteProgram(GLuint);
void deleteShader(GLuint);
void deleteQuery(GLuint);
void deleteSampler(GLuint);
}  // namespace detail

using TextureHandle = Handle<detail::deleteTexture>;  // a texture kiln::gl::Texture does not make (a buffer texture)
using BufferHandle = Handle<detail::deleteBuffer>;
using FramebufferHandle = Handle<detail::deleteFramebuffer>;
using VertexArrayHandle = Handle<detail::deleteVertexArray>;
using ProgramHandle = Handle<detail::deleteProgram>;
using ShaderHandle = Handle<detail::deleteShader>;
using QueryHandle = Handle<detail::deleteQuery>;
using SamplerHandle = Handle<detail::deleteSampler>;

// New, empty objects with one owner each (glCreate*: DSA names, usable at once).
FramebufferHandle createFramebuffer();
// A framebuffer whose one attachment is level 0 of `depthTexture` (no colour: draw
// buffer none), for a depth map a pass keeps of its own; empty when GL finds it
// incomplete.
FramebufferHandle createDepthFramebuffer(GLuint depthTexture);
VertexArrayHandle createVertexArray();
SamplerHandle createSampler();

// A texture with its shape, so binding code never has to ask GL.
class Texture {
public:
    Texture() = default;
    // target: GL_TEXTURE_2D or GL_TEXTURE_3D; levels >= 1.
    static Texture create(GLenum target, GLenum internalFormat, int w, int h, int d, int levels,
                          std::string_view debugName);
    static int fullMipCount(int w, int h, int d);

    GLuint id() const { return handle_.id(); }
    GLenum target() const { return target_; }
    GLenum internalFormat() const { return format_; }
    int width() const { return w_; }
    int height() const { return h_; }
    int depth() const { return d_; }
    int levels() const { return levels_; }
    explicit operator bool() const { return bool(handle_); }

private:
    Handle<detail::deleteTexture> handle_;
    GLenum target_ = 0, format_ = 0;
    int w_ = 0, h_ = 0, d_ = 0, levels_ = 0;
};

// A buffer object with immutable storage (glNamedBufferStorage).
class Buffer {
public:
    Buffer() = default;
    static Buffer create(GLsizeiptr bytes, const void* data, GLbitfield flags, std::string_view debugName);
    GLuint id() const { return handle_.id(); }
    GLsizeiptr size() const { return size_; }
    explicit operator bool() const { return bool(handle_); }

private:
    BufferHandle handle_;
    GLsizeiptr size_ = 0;
};

// GPU time of a span of commands: a pair of GL_TIMESTAMP queries per frame in a ring,
// read a few frames later without ever stalling the CPU on the GPU. (Timestamps, not
// GL_TIME_ELAPSED: llvmpipe returned garbage elapsed times around compute dispatches.)
class GpuTimer {
public:
    static constexpr int kRing = 4;
    void begin();
    void end();
    // Appends every measurement that finished since the last call (milliseconds,
    // oldest first) to `out`; never waits.
    template <class Container>
    void collect(Container& out) {
        for (int k = 0; k < kRing; ++k) {
            double ms;
            if (poll((next_ + k) % kRing, ms)) out.push_back(ms);
        }
    }

private:
    bool poll(int slot, double& ms);
    QueryHandle starts_[kRing], ends_[kRing];
    bool pending_[kRing] = {};
    int next_ = 0;
    bool open_ = false;
};

// Maps GL enums to readable names for error messages ("GL_RGBA16F").
const char* formatName(GLenum internalFormat);
// The formats that are read, cleared and sampled differently from colour floats.
inline bool isDepthFormat(GLenum f) { return f == GL_DEPTH_COMPONENT32F || f == GL_DEPTH_COMPONENT24; }
inline bool isIntegerFormat(GLenum f) { return f == GL_R32UI; }

}  // namespace kiln::gl
