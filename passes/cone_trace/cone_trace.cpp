// cone_trace — diffuse voxel cone tracing per pixel (Crassin et al. 2011):
// N cones over the hemisphere of the G-buffer normal march through the mipped voxel
// radiance with quadrilinear lookups; steps grow with the cone diameter. Output: the
// indirect irradiance as a cosine-weighted mean incoming radiance (composite adds
// albedo × rgb), a = ambient visibility (cone-traced AO), or with `lamp` the lamp's
// unshadowed projected solid angle at the traced surface (shaders/common/light.glsl's
// contour), upsampled with the indirect light for composite's lamp_model traced: smooth
// on a surface like the indirect light, so a sixteenth of the pixels carry it; or with
// `lamp_transmittance` bound (voxelize's), the fraction of the lamp each traced surface
// sees past the fireballs and particles (shaders/common/fire.glsl), upsampled the same
// way for composite's lamp_through_fire.
//
// Cone sets (tangent frame, z = normal; weights sum to 1):
//   1   the normal.
//   5   the normal + 4 at 45°; weights ∝ cos θ.
//   6   the normal + 5 at 60° (azimuths 72° apart), weights π/4 and 3π/20 over π: the
//       course design's set (also VCTRenderer's), with 60° cones.
//   9   the normal + 4 at 30° + 4 at 60° (azimuths offset 45°); weights ∝ cos θ.
//   16  the normal + 5 at 30° + 10 at 60°; weights ∝ cos θ.
// The aperture is a parameter of its own (60° suits 6 cones; more cones, narrower).
//
// Anisotropic chains: bind voxel_mip.aniso to `aniso` (KILN_HAS_ANISO), and the iso
// chain (always) to `voxels`: level 0 of every lookup comes from it.
// Fixed cones: bind voxel_mip.fixed_cones (mode fixed_cones) to `fixed_cones` instead
// of `aniso`. The cones are then the same for every pixel: the 12 directions of an
// icosahedron (shaders/common/fixed_cones.glsl), of which a surface traces the 6 (4 on
// the box's axis-aligned walls) in its hemisphere, weighted by cos θ; `cones` must be 6.
// Each step is one fetch from chains voxel_mip blended per direction, not three:
// the anisotropic result at the cost of an isotropic lookup.
// trace_samples N caps the samples across the picture's longer side: the stride is then
// ⌈longer side ÷ N⌉ where that exceeds trace_stride (any integer; the shaders take it as
// a uniform).
// trace_stride 2 or 4: trace one pixel in every 2×2 (4×4) block into the internal
// `samples`, with the traced surface's plane in `planes`, then a depth/normal-aware
// upsample writes `indirect`. output_divisor 2: `indirect` is half the picture's size
// and composite's bilinear lookup does the last step (the upsample is a full-screen
// pass, as dear as a stride-4 trace). output_samples N caps the
// output's texels across as trace_samples caps the samples: the upsample costs its
// pixels, and where a sample stands for 12 × 12 of them a half-size output mostly
// interpolates between the same four. Indirect light is smooth on
// surfaces, so the error stays small where a traced sample lies on the pixel's own
// surface (measured against full resolution in tests/gi and against the path-traced
// reference by kiln-bench-quality); at silhouettes the nearest sample stands in.
// reuse_frames N > 1 (strided traces): a sample within reuse_tolerance of where last
// frame's nearest sample was traced, with its normal, keeps that sample's light (and
// lamp) for up to N − 1 frames; tiles of 8×8 samples retrace in turn. The internal
// `ages` holds each sample's age and traced point; `history*` are last frame's
// samples, planes and ages (shaders/cone_trace/cone_trace.comp; README "Reusing traced
// light" for its cost and its error on moving sequences).
#include <kiln/hash.hpp>
#include <kiln/pass.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <utility>
#include <vector>

namespace {

std::vector<float> coneSet(int count) {
    // x, y, z, weight per cone.
    std::vector<float> c;
    auto ring = [&](int n, float thetaDeg, float phase) {
        const float th = thetaDeg * float(M_PI) / 180.0f;
        for (int i = 0; i < n; ++i) {
            const float ph = phase + 2.0f * float(M_PI) * float(i) / float(n);
            c.insert(c.end(), {std::sin(th) * std::cos(ph), std::sin(th) * std::sin(ph), std::cos(th), std::cos(th)});
        }
    };
    c.insert(c.end(), {0, 0, 1, 1});
    switch (count) {
        case 1: break;
        case 5: ring(4, 45, 0); break;
        case 6:
            ring(5, 60, 0);
            c[3] = 0.25f;
            for (size_t i = 7; i < c.size(); i += 4) c[i] = 0.15f;
            return c;
        case 9: ring(4, 30, 0); ring(4, 60, float(M_PI) / 4); break;
        default: ring(5, 30, 0); ring(10, 60, float(M_PI) / 10); break;
    }
    float sum = 0;
    for (size_t i = 3; i < c.size(); i += 4) sum += c[i];
    for (size_t i = 3; i < c.size(); i += 4) c[i] /= sum;
    return c;
}

// The step schedule (distance, diameter, mip level per step) depends only on the
// parameters and the voxel resolution, never on the pixel: it is compiled into the
// shader as a constant array (a parameter change builds a new variant), so the loops
// unroll and every lookup has a constant level.
//   octave      one sample where the cone's diameter is 1, 2, 4, … level-0 voxels:
//               every lookup lands exactly on a mip level (lod integral), spaced
//               1/(2·tan(aperture/2)) diameters apart (0.87 for 60° cones). llvmpipe
//               skips the second level of a LINEAR_MIPMAP_LINEAR lookup whose lod has
//               no fraction, so each lookup reads 8 texels, not 16: half the cost.
//               For apertures under ~53° the spacing exceeds one diameter; then it
//               takes as many samples per octave as keep the spacing ≤ 1 diameter.
//   continuous  the classic schedule: spacing = `step` diameters from t = 1 voxel;
//               fractional levels (quadrilinear lookups).
// The opacity of a sample is corrected to the spacing (a' = 1 − (1 − a)^(spacing/diameter)).
kiln::Defines schedule(kiln::PassContext& ctx, int res) {
    const float voxel = 2.0f / float(std::max(res, 1));
    const float tanHalf = std::tan(ctx.getFloat("aperture") * 0.5f * float(M_PI) / 180.0f);
    const float maxLod = std::log2(float(std::max(res, 1)));
    const float maxDist = ctx.getFloat("max_distance");
    const bool octave = ctx.getEnum("schedule") == "octave";
    std::string list;
    int steps = 0;
    auto add = [&](float t, float diam, float spacing) {
        char buf[160];
        std::snprintf(buf, sizeof buf, "%svec4(%.6f, %.6f, %.6f, %.6f)", steps ? ", " : "", t, diam,
                      std::clamp(std::log2(diam / voxel), 0.0f, maxLod), spacing / diam);
        list += buf;
        ++steps;
    };
    if (octave) {
        // Diameter d(t) = 2·t·tanHalf; samples at d = voxel·2^(k/n), n per octave.
        const int n = std::max(1, int(std::ceil(1.0f / (2.0f * tanHalf) - 1e-3f)));
        for (int k = 0; steps < 64; ++k) {
            const float diam = voxel * std::exp2(float(k) / float(n));
            const float t = diam / (2.0f * tanHalf);
            if (t >= maxDist) break;
            add(t, diam, t * (std::exp2(1.0f / float(n)) - 1.0f));
        }
    } else {
        const float mult = ctx.getFloat("step");
        for (float t = voxel; t < maxDist && steps < 64;) {
            const float diam = std::max(voxel, 2.0f * t * tanHalf);
            add(t, diam, diam * mult);
            t += diam * mult;
        }
    }
    if (steps == 0) add(voxel, voxel, voxel);
    return {{"KILN_CONE_STEPS", std::to_string(steps)}, {"KILN_CONE_SCHEDULE", list}};
}

class ConeTrace final : public kiln::Pass {
public:
    kiln::PassDeclaration declare() const override {
        using namespace kiln;
        PassDeclaration d;
        // The strided trace's textures: the output's size over the stride, capped at trace_samples across.
        const auto traceGrid = SizeRule::relativeOverParam("trace_stride", 1.0f, "trace_samples");
        d.input({.name = "normal", .doc = "gbuffer.normal"})
            .input({.name = "depth", .kind = TextureKind::Depth2D, .doc = "gbuffer.depth"})
            .input({.name = "voxels", .kind = TextureKind::Color3D, .doc = "voxel_mip.iso (level 0 = voxelize.radiance)"})
            .input({.name = "aniso", .kind = TextureKind::Color3D, .required = false,
                    .doc = "voxel_mip.aniso: sample the directional chains"})
            .input({.name = "fixed_cones", .kind = TextureKind::Color3D, .required = false,
                    .doc = "voxel_mip.fixed_cones: trace the fixed cone set, one fetch per step (instead of aniso)"})
            .input({.name = "lamp_transmittance", .kind = TextureKind::Color3D, .required = false,
                    .doc = "voxelize.lamp_transmittance (fire_cover on): alpha = the fraction of the lamp each "
                           "traced surface sees past the fire, upsampled for composite's lamp_through_fire "
                           "(shaders/common/fire.glsl)"})
            .output({.name = "indirect", .format = Format::RGBA16F,
                     .size = SizeRule::relativeOverParam("output_divisor", 1.0f, "output_samples"),
                     .doc = "rgb = indirect irradiance / π, a = AO (or with `lamp`: the lamp's projected solid "
                            "angle; with `lamp_transmittance` bound: the fraction of the lamp seen past the fire); "
                            "the output's size ÷ output_divisor (more where output_samples caps it)"})
            .internal({.name = "samples", .format = Format::RGBA16F, .size = traceGrid,
                       .doc = "trace_stride > 1: the traced samples"})
            .internal({.name = "planes", .format = Format::RGBA16F, .size = traceGrid,
                       .doc = "trace_stride > 1: each sample's surface, xyz = normal, w = n·(p − the voxel "
                               "volume's centre) (0,0,0 off geometry)"})
            .internal({.name = "ages", .format = Format::RGBA32F, .size = traceGrid,
                       .doc = "reuse_frames > 1: x = frames each sample's light has been kept (0: traced this frame), "
                              "yzw = the world point it was traced at"})
            .internal({.name = "history", .format = Format::RGBA16F, .size = traceGrid,
                       .doc = "reuse_frames > 1: last frame's samples"})
            .internal({.name = "history_planes", .format = Format::RGBA16F,
                       .size = traceGrid, .doc = "reuse_frames > 1: their surfaces"})
            .internal({.name = "history_ages", .format = Format::RGBA32F,
                       .size = traceGrid, .doc = "reuse_frames > 1: their ages and points"})
            .param(intChoiceParam("cones", 6, {1, 5, 6, 9, 16},
                                  "diffuse cones per pixel, around the normal (with fixed_cones bound: 6, the fixed set)"))
            .param(floatParam("aperture", 60.0f, 5.0, 150.0, "cone opening angle, degrees"))
            .param(floatParam("max_distance", 2.0f, 0.1, 3.5,
                              "cone length in the voxel volume's units (its side = 2, whatever the scene's size)"))
            .param(enumParam("schedule", "octave", {"octave", "continuous"},
                             "octave: one lookup per mip level (integral lods); continuous: spacing = step"))
            .param(floatParam("step", 1.0f, 0.2, 2.0, "continuous schedule: spacing in cone diameters"))
            .param(floatParam("start_offset", 1.0f, 0.0, 4.0, "cone origin pushed along the normal, in voxels"))
            .param(floatParam("diameter_offset", 0.5f, 0.0, 2.0,
                              "each sample pushed off the surface by this × its diameter (against self-occlusion)"))
            .param(intChoiceParam("trace_stride", 1, {1, 2, 4, 8},
                                  "trace one pixel per N×N block and upsample (depth/normal aware); 1 = every pixel"))
            .param(intParam("trace_samples", 0, 0, 4096,
                            "at most this many traced samples across the picture's longer side: the stride grows "
                            "with the picture beyond trace_stride (0: no cap). Indirect light varies over the scene, "
                            "not over pixels: a large picture needs no more samples of it than a small one"))
            .param(intChoiceParam("output_divisor", 1, {1, 2, 4},
                                  "2 (4): upsample to half (a quarter of the) resolution; composite's bilinear lookup "
                                  "does the last step"))
            .param(intParam("output_samples", 0, 0, 4096,
                            "at most this many texels of `indirect` across the picture's longer side: the divisor "
                            "grows with the picture beyond output_divisor (0: no cap), as trace_samples does the "
                            "stride's. The upsample's cost is its pixels; its edges are the traced samples'"))
            .param(floatParam("upsample_tolerance", 0.02f, 0.001, 1.0, "plane distance (world) that halves a sample's weight"))
            .param(intParam("reuse_frames", 1, 1, 8,
                            "trace_stride > output_divisor: a sample on the surface last frame's nearest sample had "
                            "keeps its light for up to N − 1 frames, tiles of 8×8 samples retracing in turn (1: every "
                            "sample traced every frame)"))
            .param(floatParam("reuse_tolerance", 0.02f, 0.0001, 0.5,
                              "reuse: how far (world) a sample may lie from where last frame's nearest sample was "
                              "traced and still take its light"))
            .param(boolParam("lamp", false,
                             "alpha = the lamp's unshadowed projected solid angle at each traced surface (its "
                             "silhouette's contour, 16 vertices), upsampled with the indirect light, for composite's "
                             "lamp_model traced; off: alpha = ambient visibility"));
        d.reads = kSceneCamera | kSceneLights;
        return d;
    }

    void execute(kiln::PassContext& ctx) override {
        if (ctx.isBound("aniso") && ctx.isBound("fixed_cones"))
            return ctx.fail("bind `aniso` or `fixed_cones`, not both: they are two ways of tracing the cones");
        if (ctx.isBound("fixed_cones") && ctx.getInt("cones") != 6)
            return ctx.fail("cones " + std::to_string(ctx.getInt("cones")) +
                            ": the fixed set traces 6 cones a pixel (4 on axis-aligned walls); set 6, or bind "
                            "`aniso` instead of `fixed_cones` for other counts");
        if (ctx.getBool("lamp") && ctx.isBound("lamp_transmittance"))
            return ctx.fail("`lamp` on and `lamp_transmittance` bound: both would fill the output's alpha; "
                            "composite's lamp_model traced reads the one, lamp_through_fire the other");
        const kiln::TextureRef& voxels = ctx.input("voxels");
        const int longest = std::max({voxels.width, voxels.height, voxels.depth});  // the schedule's voxel
        kiln::Defines defines = schedule(ctx, longest);
        defines.emplace_back("KILN_LAMP_IN_ALPHA", ctx.getBool("lamp") ? "1" : "0");
        // 16 silhouette vertices: within 1 % (tests/gi/test_lamp.cpp).
        defines.emplace_back("KILN_LAMP_SAMPLES", "16");
        // The host sized `samples` by the same rule (kiln::sizeDivisor); normal is the output's size.
        const kiln::TextureRef& normal = ctx.input("normal");
        const int stride = kiln::sizeDivisor(ctx.getInt("trace_stride"), ctx.getInt("trace_samples"), normal.width,
                                             normal.height);
        // An `indirect` pixel covers `divisor` G-buffer texels per side. A trace no
        // sparser than that goes straight into it (one texel per pixel); a sparser one
        // goes into `samples` and is upsampled.
        const int divisor = kiln::sizeDivisor(ctx.getInt("output_divisor"), ctx.getInt("output_samples"), normal.width,
                                              normal.height);
        const bool upsampled = stride > divisor;
        const int traceStep = upsampled ? stride : divisor;
        const int reuseFrames = upsampled ? ctx.getInt("reuse_frames") : 1;
        const bool reuse = reuseFrames > 1;
        defines.emplace_back("KILN_REUSE", reuse ? "1" : "0");
        defines.emplace_back("KILN_STRIDED", upsampled ? "1" : "0");
        GLuint trace = ctx.program({.stages = {"cone_trace/cone_trace.comp"}, .defines = defines});
        GLuint upsample = ctx.program({.stages = {"common/fullscreen.vert", "cone_trace/upsample.frag"}});
        if (!trace || !upsample) return;

        glUseProgram(trace);
        if (reuse) bindHistory(ctx, trace, reuseFrames);
        kiln::gl::bindTexture(trace, "u_normal", ctx.input("normal").id);
        kiln::gl::bindTexture(trace, "u_depth", ctx.input("depth").id);
        kiln::gl::bindTexture(trace, "u_voxels", voxels.id);
        kiln::gl::bindTexture(trace, "u_aniso", ctx.input("aniso").id);
        kiln::gl::bindTexture(trace, "u_fixedCones", ctx.input("fixed_cones").id);
        kiln::gl::bindTexture(trace, "u_lampTransmittance", ctx.input("lamp_transmittance").id);
        auto loc = [&](const char* n) { return glGetUniformLocation(trace, n); };
        if (!ctx.isBound("fixed_cones")) {  // the fixed set is the shader's own
            const std::vector<float> cones = coneSet(ctx.getInt("cones"));
            glUniform1i(loc("u_coneCount"), GLint(cones.size() / 4));
            glUniform4fv(loc("u_cones"), GLsizei(cones.size() / 4), cones.data());
        }
        glUniform1f(loc("u_startOffset"), ctx.getFloat("start_offset"));
        glUniform1f(loc("u_diameterOffset"), ctx.getFloat("diameter_offset"));
        glUniform1f(loc("u_voxelRes"), float(longest));
        glUniform3f(loc("u_voxelDims"), float(voxels.width), float(voxels.height), float(voxels.depth));
        glUniform1i(loc("u_stride"), traceStep);
        const kiln::TextureRef& target = upsampled ? ctx.internal("samples") : ctx.output("indirect");
        kiln::gl::bindImage(trace, "u_traced", target.id, 0, false, GL_WRITE_ONLY, GL_RGBA16F);
        kiln::gl::bindImage(trace, "u_planes", ctx.internal("planes").id, 0, false, GL_WRITE_ONLY, GL_RGBA16F);
        kiln::gl::bindImage(trace, "u_ages", ctx.internal("ages").id, 0, false, GL_WRITE_ONLY, GL_RGBA32F);
        // Where only bodies moved, only what they change (kiln/pass.hpp), grown by the
        // two traced texels each side the upsampling reads; the reuse variant keeps its
        // own history of every tile and traces all.
        const std::vector<kiln::PixelRect> rects =
            reuse ? std::vector<kiln::PixelRect>{{0, 0, target.width, target.height}}
                  : kiln::redrawRects(ctx, target.width, target.height, 2);
        for (const kiln::PixelRect& r : rects) {
            glUniform4i(loc("u_rect"), r.x, r.y, r.width, r.height);
            glDispatchCompute(GLuint((r.width + 7) / 8), GLuint((r.height + 7) / 8), 1);
        }
        // The upsample (or with stride 1 the passes after this one) fetch what it wrote;
        // the reuse variant copies it.
        glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT | GL_TEXTURE_UPDATE_BARRIER_BIT);
        if (reuse) keepHistory(ctx);

        if (upsampled) {
            if (!ctx.framebuffer({"indirect"})) return;
            glUseProgram(upsample);
            kiln::gl::bindTexture(upsample, "u_normal", ctx.input("normal").id);
            kiln::gl::bindTexture(upsample, "u_depth", ctx.input("depth").id);
            kiln::gl::bindTexture(upsample, "u_samples", ctx.internal("samples").id);
            kiln::gl::bindTexture(upsample, "u_planes", ctx.internal("planes").id);
            glUniform1i(glGetUniformLocation(upsample, "u_stride"), stride);
            glUniform1i(glGetUniformLocation(upsample, "u_outputStep"), divisor);
            glUniform1f(glGetUniformLocation(upsample, "u_planeTolerance"), ctx.getFloat("upsample_tolerance"));
            // One texel spare each side: composite reads `indirect` filtered.
            const kiln::TextureRef& indirect = ctx.output("indirect");
            if (reuse) ctx.drawFullscreenTriangle();
            else kiln::forEachRedrawRect(ctx, indirect.width, indirect.height, 1, [&] { ctx.drawFullscreenTriangle(); });
        }
    }

private:
    // Last frame's samples for the reuse variant. Everything retraces (every tile due)
    // when what the kept light depends on changed everywhere at once, which the
    // distance test cannot see: the lamp, the box or the dome (a scene reload), the
    // program (a shader or parameter edit), the textures (a resize).
    void bindHistory(kiln::PassContext& ctx, GLuint program, int reuseFrames) {
        const kiln::SceneView& scene = ctx.scene();
        uint64_t world = kiln::kFnvOffsetBasis;
        for (kiln::SceneCategory c : {kiln::kSceneLights, kiln::kScenePlanes, kiln::kSceneLightSurface})
            world = kiln::fnv1a(&scene.versions[kiln::sceneCategoryIndex(c)], sizeof(uint64_t), world);
        const GLuint history = ctx.internal("history").id;
        const bool fresh = world != world_ || program != program_ || history != history_;
        world_ = world, program_ = program, history_ = history;
        kiln::gl::bindTexture(program, "u_history", history);
        kiln::gl::bindTexture(program, "u_historyPlanes", ctx.internal("history_planes").id);
        kiln::gl::bindTexture(program, "u_historyAges", ctx.internal("history_ages").id);
        glUniformMatrix4fv(glGetUniformLocation(program, "u_prevViewProj"), 1, GL_FALSE, &previousViewProj_[0][0]);
        glUniform1i(glGetUniformLocation(program, "u_reuseFrames"), fresh ? 1 : reuseFrames);
        glUniform1i(glGetUniformLocation(program, "u_frame"), frame_++ % reuseFrames);
        glUniform1f(glGetUniformLocation(program, "u_reuseTolerance"), ctx.getFloat("reuse_tolerance"));
        previousViewProj_ = scene.frame.viewProj;
    }

    // This frame's samples become the next frame's history.
    static void keepHistory(kiln::PassContext& ctx) {
        const kiln::TextureRef& samples = ctx.internal("samples");
        for (auto [from, to] : {std::pair{"samples", "history"}, {"planes", "history_planes"}, {"ages", "history_ages"}})
            glCopyImageSubData(ctx.internal(from).id, GL_TEXTURE_2D, 0, 0, 0, 0, ctx.internal(to).id, GL_TEXTURE_2D, 0, 0,
                               0, 0, samples.width, samples.height, 1);
    }

    glm::mat4 previousViewProj_{1.0f};
    uint64_t world_ = 0;
    GLuint program_ = 0, history_ = 0;
    int frame_ = 0;
};

}  // namespace

KILN_PASS_MODULE(cone_trace, ConeTrace)
