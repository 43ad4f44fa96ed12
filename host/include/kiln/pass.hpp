// kiln/pass.hpp — the pass ABI. This comment is the pass author's manual: this header
// and your folder passes/<name>/ are all a pass author needs to open.
//
// WHAT A PASS IS
//   A shared library (a "module") in build/modules/libpass_<name>.so that exports one
//   C symbol, `kiln_pass_module`, returning a KilnPassModule descriptor. The host
//   loads it by name when a pipeline file says `"module": "<name>"`, checks its ABI
//   version before anything else, and creates one Pass object per pipeline entry.
//   A pass owns code and shaders only: the host owns its textures, its parameter
//   values and everything that must survive a reload of the module.
//
// WRITING ONE (passes/<name>/, two files; the next `cmake --build build` finds the new
// folder and re-runs CMake by itself). The example below is shipped as it stands
// (passes/tint/, shaders/tint/tint.frag): tests/integration/test_manual.cpp checks that
// this text and those files are the same, then renders with the pass and checks it tints.
//   passes/<name>/CMakeLists.txt:   kiln_add_pass(<name> <name>.cpp)
//   passes/<name>/<name>.cpp:
//
//     #include <kiln/pass.hpp>
//     class Tint final : public kiln::Pass {
//       kiln::PassDeclaration declare() const override {
//         kiln::PassDeclaration d;
//         d.input({.name = "color", .kind = kiln::TextureKind::Color2D})
//          .output({.name = "color", .format = kiln::Format::RGBA16F})
//          .param(kiln::colorParam("tint", {1, 0.5f, 0.5f}, "multiplies the colour"));
//         return d;
//       }
//       void execute(kiln::PassContext& ctx) override {
//         GLuint prog = ctx.program({.stages = {"common/fullscreen.vert", "tint/tint.frag"}});
//         if (!prog || !ctx.framebuffer({"color"})) return;  // the host shows the error
//         glUseProgram(prog);
//         kiln::gl::bindTexture(prog, "u_color", ctx.input("color").id);  // the shader's unit
//         auto t = ctx.getColor("tint");
//         glUniform3f(glGetUniformLocation(prog, "u_tint"), t[0], t[1], t[2]);
//         ctx.drawFullscreenTriangle();
//       }
//     };
//     KILN_PASS_MODULE(tint, Tint)
//
//   shaders/tint/tint.frag:
//     #version 450 core
//     layout(binding = 0) uniform sampler2D u_color;
//     uniform vec3 u_tint;
//     in vec2 v_uv;                                         // from common/fullscreen.vert
//     layout(location = 0) out vec4 o_color;
//     void main() { o_color = vec4(texture(u_color, v_uv).rgb * u_tint, 1.0); }
//
// DECLARING (see kiln/declare.hpp for every field)
//   inputs     named slots a pipeline binds to "<pass id>.<output>"; kind Color2D,
//              Depth2D or Color3D; required, or optional with a fallback texture
//              (black / white / flat normal / far depth). An unbound optional input
//              reaches your shaders as `#define KILN_HAS_<SLOT> 0` (1 when bound).
//   outputs    format, 2D/3D, size rule, mip count. Size rules: relative to the output
//              size, the output size divided by an int parameter (relativeOverParam;
//              a second int parameter may cap the texels across, kiln::sizeDivisor),
//              fixed, a side taken from an int parameter (fromParam), or the size of
//              what is bound to one of your inputs (fromInput). An output that only some
//              values of an enum parameter fill says so (producedWhen): binding it
//              otherwise is a pipeline error.
//   internals  scratch textures (ping-pong, mip levels): allocated by the host, not
//              bindable by other passes, listed in the debug view like outputs.
//   params     name, type, default, range or choices: they drive the JSON validation
//              and the debug UI. Read them in execute() with ctx.getFloat("name") etc.
//   reads      the scene categories you read (SceneCategory in kiln/declare.hpp:
//              kSceneMeshes, kSceneShadowCasters, kSceneBodies, kSceneLights, kSceneCamera,
//              ...). The geometry bits are also what ctx.drawScene() filters on.
//
// SKIPPING
//   The host re-runs a pass only when an input's version, a parameter, a scene
//   category it `reads` or the output size changed since its last run, or one of its
//   programs was rebuilt, or it is `timeDependent`. Otherwise its outputs keep their
//   contents and the skip ripples down the graph. Inside execute(),
//   ctx.nothingToDo("why") says the scene holds nothing for you: your outputs keep
//   their contents and versions, and the debug view shows the reason.
//   ctx.keepRunning(n, "why") says your outputs go on changing with nothing changed
//   upstream (feedback that converges over frames): the host runs you n more frames
//   after this run even if nothing changes. A call from one of those frames does not
//   extend them, so a paused frame settles and then costs nothing again.
//
// REDRAWING PART OF THE PICTURE
//   When the only change since your last run is bodies moving (one sphere rolling
//   among bodies at rest, nothing else), the host hands you the part of the picture they
//   can change: ctx.frame().redraw, up to two rectangles in output pixels (the moved
//   bodies' footprints with their shadows and nearby light, and one band of rows that
//   moves down the picture each such frame, so light that changes a little everywhere
//   is caught up with within kRedrawBands frames). Outside them your screen-sized
//   outputs already hold this frame's picture: a pass that draws the screen may redraw
//   only those rectangles (kiln::forEachRedrawRect sets the scissor for each, scaled
//   to your target; kiln::redrawRects gives them to a compute dispatch). A pass that
//   fills a screen-sized output from a neighbourhood of its inputs grows them by its
//   reach. frame().redrawCount is 0 whenever anything else changed (the camera, a
//   light, a parameter, a program, a size, time for a pass that reads it, a pass before
//   yours still converging, your last run failed): redraw everything. Ignoring it is
//   always correct, only slower.
//
// REUSING WHAT DID NOT CHANGE
//   A pass may keep what it computed from an input and redo only where instances
//   moved, while that input's TextureRef::setup is the one it last saw: then nothing
//   but the scene's instances changed upstream (the camera, the lights, static geometry, time,
//   parameters, programs and sizes did not). Where the movement reaches depends on the
//   producer (gbuffer: the instances' own pixels; shadow: the casters' texels; voxels:
//   the light they bounce, everywhere), so such a pass says which producers it assumes
//   and has a parameter to turn the reuse off. The instance buffer is the same at every
//   pass of a frame: a copy of it kept by the pass tells what moved since its last run
//   (composite's direct light: passes/composite).
//
// OUTPUTS NOBODY READS
//   ctx.isRead("output") is false when nothing reads that output this frame: no running
//   pass binds it, it is not the graph output, and neither the debug view, a dump nor a
//   tool asked for it (the host's requested textures). A pass may leave such an output
//   unwritten (composite's `hdr`, which only the error metrics read); what it holds is
//   then undefined. Declare it `.onlyWhenRead = true`, so the debug view knows. When
//   something starts reading it, the pass runs again in full.
//
// EXECUTING
//   ctx.input/output/internal("name") give a TextureRef (GL name + shape); asking for
//   a name you did not declare fails the pass with a message naming it.
//   ctx.program() compiles (once, cached; rebuilt on shader edits; at most 16 variants
//   per pass) and returns 0 if the shaders have an error, which the host reports as
//   `shaders/x/y.frag:LINE: message` and keeps showing until the file is fixed.
//   ctx.framebuffer({"a","b"}, "depth", mip) binds a cached FBO over your outputs or
//   internals and sets the viewport to the first attachment; it returns 0 (and fails
//   the pass) when the FBO is incomplete.
//   ctx.fail("why") stops this run: the pass shows "error" with your message, its
//   outputs keep their versions, and it runs again next frame.
//   ctx.drawScene(filter) draws the scene's meshes instanced; your vertex shader
//   includes "common/scene.glsl" for the attributes and the instance buffer.
//   ctx.drawFullscreenTriangle() for screen passes: vertex shader
//   "common/fullscreen.vert", which hands the fragment shader `in vec2 v_uv` (0..1).
//   The frame uniforms (camera, lights, output size, time, bounds, materials) are bound as
//   "common/frame.glsl" expects. The host wraps each pass in a KHR_debug group and
//   times it (GPU timestamps + CPU clock).
//
// TEXTURE UNITS AND BINDINGS
//   A unit number is written once, in the shader: `layout(binding = N)` on every
//   sampler, image and buffer block. execute() binds by the shader's name for it —
//   kiln::gl::bindTexture(program, "u_color", id), bindImage, bindStorageBuffer,
//   bindSamplerObject (kiln/gl.hpp) — which looks N up in the linked program, so the
//   C++ and the GLSL cannot drift apart. A name the program does not use (dropped in
//   this variant) binds nothing and returns false. Units are GL state shared by every
//   program of the pass: bind for each program before it runs. Reserved by the host:
//   uniform block binding 0 (common/frame.glsl) and shader storage binding 0 (the
//   instances of common/instances.glsl) while drawScene runs.
//   Stay within what OpenGL 4.5 guarantees every driver: image units 0–7 and storage
//   buffer bindings 0–7, at most 8 of each in a fragment or compute shader. llvmpipe
//   links programs past that (32 image units); NVIDIA's driver does not (its image
//   units stop at 8). The host logs a program that goes past them as a portability
//   warning at the declaration's file:line (Runtime::portabilityWarnings()).
//
// INCLUDES
//   `#include "name"` is spliced into the stage once, where it first appears, before
//   GLSL's preprocessor runs: an include inside an `#if` the preprocessor then drops
//   still counts, and a later include of the same file brings nothing (its names come
//   out undeclared). Include a shared file outside `#if`, or under the same condition
//   everywhere it is included.
//
// DERIVATIVES
//   Take dFdx/dFdy/fwidth, and texture() lookups that pick their mip level from them,
//   before a fragment shader's first `discard`: after it they are undefined. llvmpipe
//   still computes them right and NVIDIA does not, so only a GPU shows the bug
//   (tests/core/test_shader.cpp checks the shipped shaders' text for it).
//
// COST ON A CPU RASTERIZER
//   Where there is no GPU (CI, Mesa's llvmpipe) a shader runs 8 pixels or invocations
//   at a time, and an `if`, a `?:` or a loop body runs for all 8 whichever way they go:
//   a branch on a uniform or on the data saves nothing, and a lookup behind it is paid
//   everywhere (a procedural material's lookup behind `if` is paid by every pixel of a
//   G-buffer). Choose what runs with defines (ctx.program's .defines, one variant per case)
//   or by drawing each variant over only what needs it, not with branches. Texture
//   lookups are the cost: a pass gets cheaper by fewer lookups a pixel, not by cheaper
//   arithmetic — and by narrower texels: an RGBA32F fetch costs more than an RGBA16F
//   one. `discard` saves nothing (the rest of the shader runs), nor does a depth test
//   that fails everywhere (a full-screen pass masked so is still far from free). To
//   draw part of the picture, draw only that part, in squares aligned to
//   llvmpipe's 64-pixel tiles: it sets up every triangle again in each tile it touches
//   (smaller squares cost more). Measure with kiln-bench-render; the figures are in
//   docs/performance.md.
//
// GL STATE
//   Before each pass the host resets: framebuffer 0 and the viewport to the output
//   size; depth test off, depth func LESS, depth writes on; blending off, blend func
//   (ONE, ZERO); face culling off, cull face BACK; polygon offset fill off, offset 0;
//   scissor and stencil tests off; colour writes on; program 0; vertex array 0;
//   texture units 0–15 and image units 0–7 unbound; the frame uniform block and the
//   scene's instance buffer (common/instances.glsl, SSBO binding 0) bound, so a compute
//   pass can read the scene too (SceneView::firstInstance says where a category starts).
//   Anything else you change (clip control, point size, SSBO bindings other than 0)
//   is yours to restore or to set every time.
//
// MEMORY BARRIERS
//   Between passes they are the host's: after your execute() returns, the host issues
//   one glMemoryBarrier covering every way a later pass can read what you wrote
//   (texture fetches, image loads, attachments, copies, read-backs), so a producer does
//   not barrier for its consumers. Between your own dispatches and draws inside one
//   execute() (a compute pass writing an image a second dispatch reads) they are yours.
//
// RULES THAT KEEP RELOADING SAFE (see "Live editing" in the README)
//   Set every uniform in each execute(): a shader edit swaps in a new program and no
//   uniform value is carried over (so nothing needs restoring by reflection).
//   No state in statics (a reload loses it); no thread_local with destructors. State
//   in members is a cache only: a module reload or a pipeline reload that changes the
//   pass gives you a new object, but a parameter edited in the debug view runs the same
//   object again (Runtime::setParam), so key a cache on the parameters it was built
//   from. Modules are built with -fvisibility=hidden -fno-gnu-unique by kiln_add_pass
//   (cmake/KilnModule.cmake).
#pragma once

#include <algorithm>
#include <cstdint>
#include <initializer_list>
#include <string>
#include <string_view>
#include <utility>
#include <variant>
#include <vector>

#include "kiln/declare.hpp"
#include "kiln/gl.hpp"
#include "kiln/scene_view.hpp"
#include "kiln/shader.hpp"

namespace kiln {

// Bump when anything in this header (or what it includes) changes layout or vtables,
// or when what the host does for a pass changes (6: the host issues the barrier
// between passes; 7: GpuFrame's closed faces; 8: PassContext::keepRunning; 9:
// SizeRule::capSource and Lod::Medium; 10: ProgramBuild::portability; 11:
// FrameInfo::redraw; 12: TextureRef::setup; 13: Lod::Fine, and Lod::High's round cones
// by their size on screen; 14: PassContext::isRead and TextureDecl::onlyWhenRead; 15:
// kSceneMeshes (the bits after it moved up), GpuInstance's material fields and
// SceneView::materialTextures; 16: GpuFrame::voxelVolume, and the scene model's names:
// kScenePlanes, kSceneLightSurface, kSceneRoundCones, kSceneSpheres,
// kSceneGlowingSpheres, kSceneLights, GpuFrame::ringsLight/ringsDark, roundCone,
// closedFaces; 18: GpuFrame::voxelExtent, and 3D SizeRule::fromParam grids shaped by
// the scene's voxel volume), so a module built for other terms is refused by name, not run.
inline constexpr uint32_t kPassAbiVersion = 18;

struct TextureRef {
    GLuint id = 0;
    GLenum target = 0;          // GL_TEXTURE_2D / GL_TEXTURE_3D
    GLenum format = 0;          // internal format
    int width = 0, height = 0, depth = 1, levels = 1;
    bool bound = false;         // false: a fallback texture stands in
    // Changes whenever the producer (or a pass before it) wrote this texture for any
    // reason but instances moving (the bodies, particles): a parameter, a program, a
    // size, a reload, a failed run, the camera, a light, static geometry, time, a pass
    // still converging (keepRunning). While it is unchanged, the
    // texture differs from when you last read it only through instances that moved
    // (REUSING WHAT DID NOT CHANGE). 0 for a fallback.
    uint64_t setup = 0;
};

// A rectangle of pixels as glScissor takes it: lower-left corner, width and height.
struct PixelRect {
    int x = 0, y = 0, width = 0, height = 0;
    bool empty() const { return width <= 0 || height <= 0; }
    friend bool operator==(const PixelRect&, const PixelRect&) = default;
};

// The rows of the picture are refreshed in this many bands, one per frame that redraws
// only part of it (REDRAWING PART OF THE PICTURE).
inline constexpr int kRedrawBands = 8;

struct FrameInfo {
    uint64_t index = 0;
    double time = 0.0;          // simulation seconds
    double dt = 0.0;
    int outputWidth = 0, outputHeight = 0;
    // What this run must redraw, in output pixels: the whole output when redrawCount
    // is 0, else only redraw[0 .. redrawCount).
    int redrawCount = 0;
    PixelRect redraw[2];
};

class PassContext {
public:
    virtual const TextureRef& input(std::string_view slot) const = 0;
    virtual bool isBound(std::string_view slot) const = 0;
    virtual const TextureRef& output(std::string_view name) const = 0;
    virtual const TextureRef& internal(std::string_view name) const = 0;
    virtual const ParamValue& param(std::string_view name) const = 0;
    virtual const SceneView& scene() const = 0;
    virtual const FrameInfo& frame() const = 0;

    virtual GLuint program(const ProgramDesc& desc) = 0;
    virtual GLuint framebuffer(std::initializer_list<std::string_view> colorTargets,
                               std::string_view depthTarget = {}, int mipLevel = 0) = 0;
    virtual void drawFullscreenTriangle() = 0;
    virtual void drawScene(const DrawFilter& filter) = 0;
    virtual void nothingToDo(std::string_view reason) = 0;
    virtual void fail(std::string_view message) = 0;
    virtual void keepRunning(int frames, std::string_view reason) = 0;
    // Whether anything reads `output` this frame (OUTPUTS NOBODY READS).
    virtual bool isRead(std::string_view output) const = 0;

    float getFloat(std::string_view n) const { return std::get<float>(param(n)); }
    int getInt(std::string_view n) const { return std::get<int>(param(n)); }
    bool getBool(std::string_view n) const { return std::get<bool>(param(n)); }
    const std::string& getEnum(std::string_view n) const { return std::get<std::string>(param(n)); }
    Color3 getColor(std::string_view n) const { return std::get<Color3>(param(n)); }

protected:
    ~PassContext() = default;
};

class Pass {
public:
    virtual ~Pass() = default;
    virtual PassDeclaration declare() const = 0;
    virtual void execute(PassContext& ctx) = 0;
};

// The rectangles of a `width`×`height` target to redraw this run: the frame's (see
// REDRAWING PART OF THE PICTURE) scaled onto it, rounded outwards and grown by `grow`
// texels (for filters that read neighbours), clipped; or the whole target.
inline std::vector<PixelRect> redrawRects(const PassContext& ctx, int width, int height, int grow) {
    const FrameInfo& f = ctx.frame();
    if (f.redrawCount == 0 || f.outputWidth <= 0 || f.outputHeight <= 0) return {PixelRect{0, 0, width, height}};
    std::vector<PixelRect> rects;
    for (int i = 0; i < f.redrawCount; ++i) {
        const PixelRect& r = f.redraw[i];
        auto lo = [&](int v, int target, int output) { return std::max(0, int(int64_t(v) * target / output) - grow); };
        auto hi = [&](int v, int target, int output) {
            return std::min(target, int((int64_t(v) * target + output - 1) / output) + grow);
        };
        const int x0 = lo(r.x, width, f.outputWidth), x1 = hi(r.x + r.width, width, f.outputWidth);
        const int y0 = lo(r.y, height, f.outputHeight), y1 = hi(r.y + r.height, height, f.outputHeight);
        if (x1 > x0 && y1 > y0) rects.push_back({x0, y0, x1 - x0, y1 - y0});
    }
    return rects;
}

// Runs `draw` once per rectangle of redrawRects with the scissor test on it, turned
// off again after; once with the scissor off when the whole output is to be redrawn.
template <class Draw>
void forEachRedrawRect(const PassContext& ctx, int width, int height, int grow, Draw&& draw) {
    if (ctx.frame().redrawCount == 0) return (void)draw();
    glEnable(GL_SCISSOR_TEST);
    for (const PixelRect& r : redrawRects(ctx, width, height, grow)) {
        glScissor(r.x, r.y, r.width, r.height);
        draw();
    }
    glDisable(GL_SCISSOR_TEST);
}

// Binds the scene's ray-tracing buffers and material textures (SceneView::rayMeshes)
// for shaders/common/ray_meshes.glsl, and sets its uniforms in `program` (which must be
// in use).
inline void bindRayMeshes(const SceneView& scene, GLuint program) {
    const RayMeshes& r = scene.rayMeshes;
    const std::pair<unsigned, uint32_t> buffers[] = {
        {kRayEmitterBinding, r.emitters}, {kRayNodeBinding, r.nodes},       {kRayTriangleBinding, r.triangles},
        {kRayInstanceBinding, r.instances}, {kRayVertexBinding, r.vertices}, {kRaySurfaceBinding, r.surface},
        {kRayIndexBinding, r.indices}};
    for (const auto& [binding, buffer] : buffers)
        if (buffer) glBindBufferBase(GL_SHADER_STORAGE_BUFFER, binding, buffer);
    if (scene.materialTextures[0]) glBindTextureUnit(kRayColorLayersUnit, scene.materialTextures[0]);
    if (scene.materialTextures[1]) glBindTextureUnit(kRayDataLayersUnit, scene.materialTextures[1]);
    glUniform1ui(glGetUniformLocation(program, "u_rayTopRoot"), r.topRoot);
    glUniform1ui(glGetUniformLocation(program, "u_rayInstanceCount"), r.nodes ? r.instanceCount : 0u);
    glUniform1ui(glGetUniformLocation(program, "u_rayEmitterCount"), r.emitters ? r.emitterCount : 0u);
    glUniform1f(glGetUniformLocation(program, "u_rayEmittedPower"), r.emittedPower);
}

}  // namespace kiln

extern "C" {
// The layout of this struct's first field never changes, so a host can read the
// ABI version of any module before trusting anything else in it.
struct KilnPassModule {
    uint32_t abiVersion;
    const char* name;
    kiln::Pass* (*create)();
    void (*destroy)(kiln::Pass*);
};
}

#define KILN_PASS_MODULE(NAME, CLASS)                                                        \
    namespace {                                                                              \
    kiln::Pass* kilnCreatePass() { return new CLASS(); }                                     \
    void kilnDestroyPass(kiln::Pass* p) { delete p; }                                        \
    const KilnPassModule kilnPassModule{kiln::kPassAbiVersion, #NAME, &kilnCreatePass,       \
                                        &kilnDestroyPass};                                   \
    }                                                                                        \
    extern "C" __attribute__((visibility("default"))) const KilnPassModule* kiln_pass_module() { \
        return &kilnPassModule;                                                              \
    }
