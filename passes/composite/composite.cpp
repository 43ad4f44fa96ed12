// composite — the final image: direct light from the lamp (the cap emitter of
// shaders/common/light.glsl: its silhouette's contour integral, `lamp_samples`
// quadrature points, cone_trace's traced samples, or n · its vector irradiance from a
// grid this pass builds when the lamp changes) on the G-buffer (PCF or PCSS
// shadows from `shadow_map`), plus albedo × indirect irradiance (cone_trace), emission
// and bloom; tonemap and gamma. Bloom is computed before this pass from the G-buffer's
// emitted radiance (see passes/bloom), so no separate "lighting" pass is needed.
//
// keep_direct: the lamp's light on the G-buffer (before the fire dims it) is kept in
// `direct` and recomputed only over the tiles of the picture that instances moving
// since the last run can have changed (shaders/composite/moved_tiles.comp); the rest of
// the picture is shaded from the kept light. It assumes what gbuffer and shadow write:
// the G-buffer changes only where instances are drawn, the shadow map only where
// casters are (kiln/pass.hpp, REUSING WHAT DID NOT CHANGE); anything else that changed
// upstream (TextureRef::setup), the camera, the lamp, the box, a parameter, a program
// or a size recomputes every pixel.
#include <kiln/gamma_fit.hpp>
#include <kiln/pass.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

namespace {

class Composite final : public kiln::Pass {
public:
    ~Composite() override {
        if (countFence_) glDeleteSync(countFence_);
    }

    kiln::PassDeclaration declare() const override {
        using namespace kiln;
        PassDeclaration d;
        // The G-buffer inputs are read texel for texel (the output's size); the indirect
        // light, the bloom and the shadow map are filtered lookups at any size.
        d.input({.name = "albedo", .doc = "output-sized"})
            .input({.name = "normal", .doc = "output-sized"})
            .input({.name = "depth", .kind = TextureKind::Depth2D, .doc = "output-sized"})
            .input({.name = "emissive", .required = false, .fallback = Fallback::Black,
                    .doc = "output-sized; alpha 2: a particle hides the surface, its emission alone shows"})
            .input({.name = "shadow_map", .kind = TextureKind::Depth2D, .required = false})
            .input({.name = "indirect", .required = false, .fallback = Fallback::Black})
            .input({.name = "bloom", .required = false, .fallback = Fallback::Black})
            .input({.name = "light_shadows", .kind = TextureKind::Depth2D, .required = false,
                    .fallback = Fallback::FarDepth,
                    .doc = "the punctual lights' shadow atlas (lights.shadow_atlas); read only when the scene has them"})
            .output({.name = "color", .format = Format::RGBA8, .doc = "tonemapped, gamma-encoded final image"})
            .output({.name = "hdr", .format = Format::RGBA16F,
                     .doc = "linear radiance before bloom, exposure and tonemapping; written only when read",
                     .onlyWhenRead = true})
            .internal({.name = "direct", .format = Format::RGBA16F,
                       .doc = "keep_direct: the lamp's light on each pixel before the fire dims it, kept between runs"})
            .param(floatParam("exposure", 1.0f, 0.01, 16.0, "scales radiance before tonemapping"))
            .param(floatParam("ambient", 0.03f, 0.0, 1.0, "constant fill light when no indirect input is bound"))
            .param(enumParam("tonemap", "aces", {"aces", "reinhard", "clamp"}))
            .param(floatParam("gamma", 2.2f, 1.0, 3.0))
            .param(intChoiceParam("pcf", 5, {1, 3, 5, 7, 9},
                                  "shadow filter about k+1 texels wide from ((k+1)/2)² bilinear depth comparisons; 1 = one"))
            .param(enumParam("fireball_light", "voxels", {"voxels", "analytic"},
                             "voxels: the fireballs light surfaces through the cones (cone_trace.indirect); "
                             "analytic: here, each a sphere of its radiance, unshadowed (pair with "
                             "voxelize.fireball_emission 0)"))
            .param(enumParam("shadow_filter", "pcf", {"pcf", "pcss"},
                             "pcf: the fixed filter of `pcf`; pcss: a penumbra sized by the lamp and the blockers' "
                             "distance (25 depth reads + 16 bilinear comparisons a pixel)"))
            .param(floatParam("indirect_strength", 1.0f, 0.0, 8.0, "scales the bound indirect irradiance (1 = physical)"))
            .param(floatParam("shadow_bias", 0.0005f, 0.0, 0.05, "depth bias of the shadow test"))
            .param(enumParam("lamp_model", "contour", {"contour", "points", "traced", "field"},
                             "the lamp's irradiance: contour = its silhouette as a polygon (exact up to the "
                             "polygon, also next to the dome); points = a quadrature over the cap (lobes near it); "
                             "traced = the contour evaluated by cone_trace (its `lamp` on) where it traces, read "
                             "from the indirect input's alpha; field = n · the lamp's vector irradiance, from a "
                             "grid of lamp_field_size² over (distance from its axis, height) built when the lamp changes (one "
                             "lookup a pixel)"))
            .param(floatParam("lamp_near_field", 0.2f, 0.0, 4.0,
                              "lamp_model traced or field: within this many metres of the dome the contour is "
                              "evaluated per pixel (the irradiance changes faster there than the samples); 0 "
                              "compiles that out"))
            .param(intChoiceParam("lamp_field_size", 256, {32, 64, 128, 256, 512},
                                  "lamp_model field: nodes per side of the lamp's axisymmetric grid (distance from "
                                  "its axis x height; 256: 5.5 x 7.8 mm apart, 256 KiB)"))
            .param(boolParam("lamp_through_fire", false,
                             "multiply the lamp's light by `indirect`'s alpha: the fraction of the lamp seen past "
                             "the fireballs and particles, from cone_trace with `lamp_transmittance` bound "
                             "(voxelize's fire_cover on)"))
            .param(intChoiceParam("lamp_samples", 32, {4, 8, 16, 32, 64},
                                  "vertices of the lamp's silhouette (contour) or quadrature points over its cap (points)"))
            .param(boolParam("keep_direct", true,
                             "keep the lamp's light on the picture and recompute it only where instances moved "
                             "(and their shadows); every pixel when the camera, the lamp or anything upstream "
                             "but instances changed. Not with lamp_model traced or shadow_filter pcss (they "
                             "recompute every pixel). Assumes the G-buffer and shadow map of gbuffer and shadow (whose "
                             "particles write only emission: they are not followed)"))
            .param(intChoiceParam("direct_tile", 64, {16, 32, 64},
                                  "keep_direct: side in pixels of the square tiles the lamp's light is recomputed "
                                  "over. 64: llvmpipe's own tiles (smaller ones recompute less of the "
                                  "picture but cost more: llvmpipe sets up each small triangle in each "
                                  "of its tiles)"));
        d.reads = kSceneLights | kSceneCamera | kSceneGlowingSpheres;
        return d;
    }

    void execute(kiln::PassContext& ctx) override {
        const std::string& lampModel = ctx.getEnum("lamp_model");
        const bool pcss = ctx.getEnum("shadow_filter") == "pcss";
        // The lamp's light depends on the pixel's surface and the shadow map only, but
        // for `traced` (cone_trace's samples, every frame) and pcss (a blocker search
        // of unbounded reach).
        const bool keep = ctx.getBool("keep_direct") && lampModel != "traced" && !pcss;
        // `hdr` only when something reads it (the error metrics, the debug view): a
        // target nothing in the default pipeline reads is not worth its cost on llvmpipe.
        hdr_ = ctx.isRead("hdr");
        // The display's gamma as a polynomial where it fits (kiln/gamma_fit.hpp).
        if (ctx.getFloat("gamma") != fittedGamma_)
            fittedGamma_ = ctx.getFloat("gamma"), gammaFit_ = kiln::fitGamma(fittedGamma_);
        auto variant = [&](bool nearField, int direct, bool tiles) {
            return ctx.program({.stages = {tiles ? "composite/tiles.vert" : "common/fullscreen.vert", "composite/composite.frag"},
                                .defines = {{"KILN_LAMP_SAMPLES", std::to_string(ctx.getInt("lamp_samples"))},
                                            {"KILN_LAMP_CONTOUR", lampModel == "points" ? "0" : "1"},
                                            {"KILN_LAMP_TRACED", lampModel == "traced" ? "1" : "0"},
                                            {"KILN_LAMP_FIELD", lampModel == "field" ? "1" : "0"},
                                            {"KILN_LAMP_NEAR_FIELD", nearField ? "1" : "0"},
                                            {"KILN_PCF", std::to_string(ctx.getInt("pcf"))},
                                            {"KILN_PCSS", pcss ? "1" : "0"},
                                            {"KILN_LAMP_THROUGH_FIRE", ctx.getBool("lamp_through_fire") ? "1" : "0"},
                                            {"KILN_FIREBALLS_ANALYTIC", ctx.getEnum("fireball_light") == "analytic" ? "1" : "0"},
                                            {"KILN_PUNCTUAL", ctx.scene().frame.punctualCount.x > 0 ? "1" : "0"},
                                            {"KILN_DIRECT", std::to_string(direct)},
                                            {"KILN_HDR", hdr_ ? "1" : "0"},
                                            {"KILN_GAMMA_FIT", gammaFit_.usable() ? "1" : "0"}}});
        };
        // keep: the recomputed tiles write the kept light (1), the others read it (2).
        GLuint program = variant(false, keep ? 1 : 0, keep);
        if (!program) return;
        const bool nearField = (lampModel == "traced" || lampModel == "field") && ctx.getFloat("lamp_near_field") > 0.0f;
        if (lampModel == "field" && !buildLampField(ctx)) return;
        GLuint nearProgram = nearField ? variant(true, keep ? 1 : 0, keep) : 0;
        if (nearField && !nearProgram) return;
        GLuint cachedProgram = keep ? variant(false, 2, true) : 0;
        if (keep && !cachedProgram) return;
        if (lampModel == "traced" && ctx.getBool("lamp_through_fire"))
            return ctx.fail("lamp_model traced and lamp_through_fire both read `indirect`'s alpha (the lamp, or its "
                            "transmittance through the fire): pick one");
        if (ctx.getBool("lamp_through_fire") && !ctx.isBound("indirect"))
            return ctx.fail("lamp_through_fire reads the lamp's transmittance through the fire from `indirect` "
                            "(cone_trace.indirect with cone_trace's `lamp_transmittance` bound): bind it, or turn it off");
        if (lampModel == "traced" && !ctx.isBound("indirect"))
            return ctx.fail("lamp_model traced reads the lamp from `indirect` (cone_trace.indirect with cone_trace's "
                            "`lamp` on): bind it, or use lamp_model contour");
        // The shadow map is read through hardware comparison (sampler2DShadow): each
        // lookup a bilinear blend of four depth tests. A sampler object, so the shadow
        // pass's texture keeps its own state for the passes that read raw depth.
        if (!compareSampler_) {
            compareSampler_ = kiln::gl::createSampler();
            glSamplerParameteri(compareSampler_.id(), GL_TEXTURE_MIN_FILTER, GL_LINEAR);
            glSamplerParameteri(compareSampler_.id(), GL_TEXTURE_MAG_FILTER, GL_LINEAR);
            glSamplerParameteri(compareSampler_.id(), GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
            glSamplerParameteri(compareSampler_.id(), GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
            glSamplerParameteri(compareSampler_.id(), GL_TEXTURE_COMPARE_MODE, GL_COMPARE_REF_TO_TEXTURE);
            glSamplerParameteri(compareSampler_.id(), GL_TEXTURE_COMPARE_FUNC, GL_LEQUAL);
        }
        const kiln::TextureRef& color = ctx.output("color");
        const glm::vec4 lamp = ctx.scene().frame.lightPos;
        const kiln::PixelRect nearRect =
            nearField ? screenRect(ctx, glm::vec3(lamp), lamp.w + ctx.getFloat("lamp_near_field")) : kiln::PixelRect{};
        if (keep) {
            const Kept kept = drawKeepingDirect(ctx, program, nearProgram, cachedProgram, nearRect);
            if (kept == Kept::Failed) return;
            if (kept == Kept::Drawn) {
                kiln::gl::bindSamplerObject(program, "u_shadowMap", 0);
                return;
            }
            // Most of the picture moved: every pixel computed, nothing kept, by the
            // variants that write no `direct`.
            program = variant(false, 0, false);
            nearProgram = nearField ? variant(true, 0, false) : 0;
            if (!program || (nearField && !nearProgram)) return;
        }
        cacheKey_.reset();
        if (!targets(ctx, false)) return;
        // Where only bodies moved, only what they change (kiln/pass.hpp).
        kiln::forEachRedrawRect(ctx, color.width, color.height, 0, [&] {
            bindInputs(ctx, program);
            ctx.drawFullscreenTriangle();
        });
        // The near field again, per pixel, over its screen rectangle only (within each
        // rectangle to redraw).
        if (nearField) {
            glEnable(GL_SCISSOR_TEST);
            for (const kiln::PixelRect& part : kiln::redrawRects(ctx, color.width, color.height, 0)) {
                const kiln::PixelRect r = intersect(nearRect, part);
                if (r.empty()) continue;
                glScissor(r.x, r.y, r.width, r.height);
                bindInputs(ctx, nearProgram);
                ctx.drawFullscreenTriangle();
            }
            glDisable(GL_SCISSOR_TEST);
        }
        kiln::gl::bindSamplerObject(program, "u_shadowMap", 0);  // the host resets textures, not samplers
    }

private:
    struct FieldKey {  // what the lamp field was built for
        uint64_t lightVersion = 0;
        int side = 0;
        GLuint program = 0;
        bool operator==(const FieldKey&) const = default;
    };

    static kiln::PixelRect intersect(const kiln::PixelRect& a, const kiln::PixelRect& b) {
        const int x0 = std::max(a.x, b.x), x1 = std::min(a.x + a.width, b.x + b.width);
        const int y0 = std::max(a.y, b.y), y1 = std::min(a.y + a.height, b.y + b.height);
        return {x0, y0, std::max(0, x1 - x0), std::max(0, y1 - y0)};
    }

    // The framebuffer of `color`, `hdr` when something reads it, and with `direct` the
    // kept light (composite.frag's outputs in that order: KILN_HDR, KILN_DIRECT 1).
    GLuint targets(kiln::PassContext& ctx, bool direct) const {
        if (direct) return hdr_ ? ctx.framebuffer({"color", "hdr", "direct"}) : ctx.framebuffer({"color", "direct"});
        return hdr_ ? ctx.framebuffer({"color", "hdr"}) : ctx.framebuffer({"color"});
    }

    void bindInputs(kiln::PassContext& ctx, GLuint program) const {
        glUseProgram(program);
        // Each input to the sampler of its name (u_shadow_map is u_shadowMap).
        for (auto [slot, sampler] : {std::pair{"albedo", "u_albedo"}, {"normal", "u_normal"}, {"depth", "u_depth"},
                                     {"emissive", "u_emissive"}, {"shadow_map", "u_shadowMap"},
                                     {"indirect", "u_indirect"}, {"bloom", "u_bloom"}})
            kiln::gl::bindTexture(program, sampler, ctx.input(slot).id);
        kiln::gl::bindSamplerObject(program, "u_shadowMap", compareSampler_.id());
        kiln::gl::bindTexture(program, "u_shadowDepth", ctx.input("shadow_map").id);  // pcss only
        kiln::gl::bindTexture(program, "u_lampField", lampField_.id());  // field only
        kiln::gl::bindTexture(program, "u_direct", ctx.internal("direct").id);  // reading the kept light only
        kiln::gl::bindTexture(program, "u_lightShadows", ctx.input("light_shadows").id);  // punctual lights only
        const std::string& tonemap = ctx.getEnum("tonemap");
        glUniform1f(glGetUniformLocation(program, "u_exposure"), ctx.getFloat("exposure"));
        glUniform1f(glGetUniformLocation(program, "u_ambient"), ctx.getFloat("ambient"));
        glUniform1f(glGetUniformLocation(program, "u_gamma"), ctx.getFloat("gamma"));
        glUniform4fv(glGetUniformLocation(program, "u_gammaFit"), 1, gammaFit_.c.data());
        glUniform1i(glGetUniformLocation(program, "u_tonemap"), tonemap == "aces" ? 0 : tonemap == "reinhard" ? 1 : 2);
        glUniform1f(glGetUniformLocation(program, "u_shadowBias"), ctx.getFloat("shadow_bias"));
        glUniform1f(glGetUniformLocation(program, "u_indirectStrength"), ctx.getFloat("indirect_strength"));
        glUniform1f(glGetUniformLocation(program, "u_lampNearField"), ctx.getFloat("lamp_near_field"));
        glUniform1i(glGetUniformLocation(program, "u_firstFireball"), int(ctx.scene().firstInstance(kiln::kSceneGlowingSpheres)));
        glUniform1i(glGetUniformLocation(program, "u_fireballCount"), int(ctx.scene().count(kiln::kSceneGlowingSpheres)));
    }

    // Everything but the moving instances that the kept light was computed from: when
    // any of it differs from the last run's, every pixel is recomputed.
    struct CacheKey {
        std::array<unsigned char, sizeof(kiln::GpuFrame)> frame{};  // the camera, the lamp, the look; not time
        std::array<uint64_t, 4> setups{};                           // albedo, normal, depth, shadow_map
        std::array<GLuint, 6> textures{};                           // those four, the kept light, the lamp field
        std::array<GLuint, 2> programs{};                           // the two that compute it
        std::array<uint32_t, kiln::kSceneGeometryCount> counts{};
        float shadowBias = 0.0f, nearField = 0.0f;
        FieldKey field;
        bool operator==(const CacheKey&) const = default;
    };

    CacheKey cacheKey(kiln::PassContext& ctx, GLuint program, GLuint nearProgram) const {
        CacheKey k;
        kiln::GpuFrame frame = ctx.scene().frame;
        frame.time = glm::vec4(0.0f);
        std::memcpy(k.frame.data(), &frame, sizeof frame);
        size_t n = 0;
        for (const char* slot : {"albedo", "normal", "depth", "shadow_map"}) {
            k.setups[n] = ctx.input(slot).setup;
            k.textures[n++] = ctx.input(slot).id;
        }
        k.textures[4] = ctx.internal("direct").id;
        k.textures[5] = lampField_.id();
        k.programs = {program, nearProgram};
        std::copy(std::begin(ctx.scene().counts), std::end(ctx.scene().counts), k.counts.begin());
        // The particles change none of the G-buffer the kept light comes from (gbuffer
        // writes only their emission), nor do they cast shadows.
        k.counts[size_t(kiln::sceneCategoryIndex(kiln::kSceneParticles))] = 0;
        k.shadowBias = ctx.getFloat("shadow_bias");
        k.nearField = ctx.getFloat("lamp_near_field");
        k.field = builtField_;
        return k;
    }

    // keep_direct: which tiles moved (moved_tiles.comp, tile_lists.comp), the lamp's
    // light recomputed and kept over those, the rest shaded from what was kept. When
    // most of the picture moved at the last count, drawing it in tiles costs more than
    // the whole (all tiles recomputed cost more than the plain pass, and many fireballs
    // move most of the tiles): DrawWhole, and the tiles are only counted.
    enum class Kept { Drawn, DrawWhole, Failed };
    Kept drawKeepingDirect(kiln::PassContext& ctx, GLuint program, GLuint nearProgram, GLuint cachedProgram,
                           const kiln::PixelRect& nearRect) {
        GLuint marking[3];  // moved_tiles.comp's parts: the casters, the other instances, what lies in shadows
        for (int part = 0; part < 3; ++part)
            if (!(marking[part] = ctx.program({.stages = {"composite/moved_tiles.comp"},
                                               .defines = {{"KILN_PART", std::to_string(part)}}})))
                return Kept::Failed;
        GLuint lists = ctx.program({.stages = {"composite/tile_lists.comp"}});
        if (!lists) return Kept::Failed;
        const kiln::SceneView& scene = ctx.scene();
        const kiln::TextureRef& color = ctx.output("color");
        const int tileSize = ctx.getInt("direct_tile");
        const int tilesAcross = (color.width + tileSize - 1) / tileSize;
        const int tilesDown = (color.height + tileSize - 1) / tileSize;
        const uint32_t tileCount = uint32_t(tilesAcross * tilesDown);
        // The particles, last in the instances, are not followed (cacheKey).
        const uint32_t first = scene.firstInstance(kiln::kSceneRoundCones), end = scene.firstInstance(kiln::kSceneParticles);

        // The share of the tiles that moved at the last count the GPU has finished.
        if (countFence_ && glClientWaitSync(countFence_, 0, 0) != GL_TIMEOUT_EXPIRED) {
            uint32_t movedTiles = 0;
            glGetNamedBufferSubData(movedCount_.id(), 0, sizeof movedTiles, &movedTiles);
            movedShare_ = countedTiles_ ? double(movedTiles) / countedTiles_ : 0.0;
            glDeleteSync(countFence_);
            countFence_ = nullptr;
        }
        // No instance moved since the last run (the scene paused or asleep): none of
        // the tiles would be marked.
        const std::array<uint64_t, 3> instances{scene.version(kiln::kSceneRoundCones), scene.version(kiln::kSceneSpheres),
                                                scene.version(kiln::kSceneGlowingSpheres)};
        if (instances == instancesSeen_) movedShare_ = 0.0;
        instancesSeen_ = instances;
        // Back from the whole at a lower share than away to it: the first run in tiles
        // recomputes them all.
        const bool inTiles = movedShare_ <= (drawingWhole_ ? kTilesBackBelow : kTilesUpTo);
        drawingWhole_ = !inTiles;
        // Drawing whole, the tiles are only counted, to know when to come back to them:
        // every kCountWholeEvery-th run, the run before it keeping the instances to
        // compare with (marking many fireballs' thousands of particles each run, when
        // they were followed, cost composite time for nothing drawn).
        bool keepOnly = false;
        if (!inTiles) {
            const uint32_t phase = wholeRuns_++ % kCountWholeEvery;
            if (phase + 2 < kCountWholeEvery) return Kept::DrawWhole;
            keepOnly = phase + 2 == kCountWholeEvery;
            if (keepOnly) previousKept_ = false;
        } else {
            wholeRuns_ = 0;
        }

        const CacheKey key = cacheKey(ctx, program, nearProgram);
        bool reuse = inTiles && cacheKey_ && *cacheKey_ == key;
        cacheKey_.reset();  // set again once this run has drawn
        if (!previous_ || previous_.size() < GLsizeiptr(end * sizeof(kiln::GpuInstance))) {
            const GLsizeiptr bytes = GLsizeiptr(std::max<uint32_t>(2 * end, 64) * sizeof(kiln::GpuInstance));
            previous_ = kiln::gl::Buffer::create(bytes, nullptr, 0, "composite.previous_instances");
            previousKept_ = false;
            reuse = false;
        }
        const GLsizeiptr listBytes = GLsizeiptr((kListsStart + 2 * tileCount) * sizeof(uint32_t));
        if (tileLists_.size() != listBytes) {
            tileLists_ = kiln::gl::Buffer::create(listBytes, nullptr, GL_DYNAMIC_STORAGE_BIT, "composite.tile_lists");
            GLuint texture = 0;
            glCreateTextures(GL_TEXTURE_BUFFER, 1, &texture);
            glTextureBuffer(texture, GL_R32UI, tileLists_.id());
            tileListsTexture_ = kiln::gl::TextureHandle(texture);
            const std::vector<uint32_t> zeros(tileCount, 0u);
            tileMarks_ = kiln::gl::Buffer::create(GLsizeiptr(tileCount * sizeof(uint32_t)), zeros.data(), 0,
                                                  "composite.tile_marks");
            reuse = false;
        }
        auto uniform = [](GLuint p, const char* name) { return glGetUniformLocation(p, name); };

        // Which tiles instances moving since the last run can have changed: the movers
        // (and the casters' pyramids), then what lies in those.
        const uint32_t casters = scene.count(kiln::kSceneShadowCasters);
        const GLsizeiptr pyramidBytes = GLsizeiptr(16 + 2 * 2 * std::max<uint32_t>(casters, 1) * 16);
        if (pyramids_.size() != pyramidBytes)
            pyramids_ = kiln::gl::Buffer::create(pyramidBytes, nullptr, GL_DYNAMIC_STORAGE_BIT, "composite.shadow_pyramids");
        const uint32_t none = 0;
        glNamedBufferSubData(pyramids_.id(), 0, sizeof none, &none);
        const kiln::TextureRef& shadow = ctx.input("shadow_map");
        const uint32_t compared = std::max(end, previousKept_ ? previousEnd_ : 0u);
        const uint32_t castersEnd = first + casters;
        const uint32_t from[3] = {first, castersEnd, first}, to[3] = {castersEnd, compared, end};
        for (int part = 0; part < 3; ++part) {
            const GLuint p = marking[part];
            glUseProgram(p);
            kiln::gl::bindStorageBuffer(p, "PreviousInstances", previous_.id());
            kiln::gl::bindStorageBuffer(p, "TileMarks", tileMarks_.id());
            kiln::gl::bindStorageBuffer(p, "ShadowPyramids", pyramids_.id());
            glUniform1ui(uniform(p, "u_from"), from[part]);
            glUniform1ui(uniform(p, "u_to"), to[part]);
            glUniform1ui(uniform(p, "u_end"), end);
            glUniform1ui(uniform(p, "u_previousEnd"), previousKept_ ? previousEnd_ : 0u);
            glUniform1ui(uniform(p, "u_tumblersEnd"), first + scene.count(kiln::kSceneRoundCones));
            glUniform1i(uniform(p, "u_compare"), previousKept_ ? 1 : 0);
            glUniform2i(uniform(p, "u_tiles"), tilesAcross, tilesDown);
            glUniform1i(uniform(p, "u_tileSize"), tileSize);
            // The filter's farthest lookup is (k+1)/2 − 1 texels off the pixel's point,
            // and each is bilinear: one texel more; one more for rounding.
            glUniform1f(uniform(p, "u_shadowReachTexels"), float((ctx.getInt("pcf") + 1) / 2 + 1));
            glUniform2f(uniform(p, "u_shadowTexel"), shadow.bound ? 1.0f / float(shadow.width) : 0.0f,
                        shadow.bound ? 1.0f / float(shadow.height) : 0.0f);
            if (to[part] > from[part]) glDispatchCompute((to[part] - from[part] + 63) / 64, 1, 1);
            glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
        }
        previousEnd_ = end, previousKept_ = true;
        if (keepOnly) return Kept::DrawWhole;

        // The two lists: their draw commands (vertices counted on the GPU, one instance)
        // and the count of moved tiles, read back a run later.
        const uint32_t header[kListsStart] = {0, 1, 0, 0, 0, 1, 0, 0, 0, 0, 0, 0};
        glNamedBufferSubData(tileLists_.id(), 0, sizeof header, header);
        glUseProgram(lists);
        kiln::gl::bindStorageBuffer(lists, "TileMarks", tileMarks_.id());
        kiln::gl::bindStorageBuffer(lists, "TileLists", tileLists_.id());
        glUniform1ui(uniform(lists, "u_tileCount"), tileCount);
        glUniform1i(uniform(lists, "u_all"), reuse ? 0 : 1);
        glDispatchCompute((tileCount + 63) / 64, 1, 1);
        glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_COMMAND_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT |
                        GL_TEXTURE_FETCH_BARRIER_BIT);  // tiles.vert reads the lists as a buffer texture
        if (!countFence_) {
            if (!movedCount_) movedCount_ = kiln::gl::Buffer::create(sizeof(uint32_t), nullptr, 0, "composite.moved_tiles");
            glCopyNamedBufferSubData(tileLists_.id(), movedCount_.id(), kMovedCountAt * sizeof(uint32_t), 0,
                                     sizeof(uint32_t));
            countFence_ = glFenceSync(GL_SYNC_GPU_COMMANDS_COMPLETE, 0);
            countedTiles_ = tileCount;
        }
        if (!inTiles) return Kept::DrawWhole;

        if (!vertexArray_) vertexArray_ = kiln::gl::createVertexArray();
        glBindVertexArray(vertexArray_.id());
        glBindBuffer(GL_DRAW_INDIRECT_BUFFER, tileLists_.id());
        auto drawList = [&](GLuint p, bool recomputed) {
            bindInputs(ctx, p);
            kiln::gl::bindTexture(p, "u_tileLists", tileListsTexture_.id());
            glUniform1ui(uniform(p, "u_listStart"), kListsStart + (recomputed ? 0u : tileCount));
            glUniform1i(uniform(p, "u_tileSize"), tileSize);
            glUniform1i(uniform(p, "u_tilesAcross"), tilesAcross);
            glDrawArraysIndirect(GL_TRIANGLES, reinterpret_cast<const void*>(recomputed ? 0 : 4 * sizeof(uint32_t)));
        };
        // The moved tiles, whole (the kept light must be right everywhere, whatever
        // the frame asks to redraw), and the near field again over its rectangle.
        if (!targets(ctx, true)) return Kept::Failed;
        drawList(program, true);
        if (nearProgram && !nearRect.empty()) {
            glEnable(GL_SCISSOR_TEST);
            glScissor(nearRect.x, nearRect.y, nearRect.width, nearRect.height);
            drawList(nearProgram, true);
            glDisable(GL_SCISSOR_TEST);
        }
        // The rest from the kept light (where only bodies moved, within the rectangles
        // the frame redraws: kiln/pass.hpp).
        if (!targets(ctx, false)) return Kept::Failed;
        kiln::forEachRedrawRect(ctx, color.width, color.height, 0, [&] { drawList(cachedProgram, false); });
        glBindBuffer(GL_DRAW_INDIRECT_BUFFER, 0);
        glBindVertexArray(0);
        cacheKey_ = key;
        return Kept::Drawn;
    }

    // lamp_model field: the grid (the pass's own texture, made only in this mode: 1 MiB
    // at 512²), rebuilt when the lamp, the grid's size or its shader changed. False when
    // the pass failed.
    bool buildLampField(kiln::PassContext& ctx) {
        GLuint builder = ctx.program({.stages = {"common/lamp_field.comp"},
                                      .defines = {{"KILN_LAMP_SAMPLES", std::to_string(ctx.getInt("lamp_samples"))}}});
        if (!builder) return false;
        const int side = ctx.getInt("lamp_field_size");
        if (!lampField_ || lampField_.width() != side)
            lampField_ = kiln::gl::Texture::create(GL_TEXTURE_2D, GL_RG16F, side, side, 1, 1, "composite.lamp_field");
        const FieldKey key{ctx.scene().version(kiln::kSceneLights), side, builder};
        if (key == builtField_) return true;
        glUseProgram(builder);
        kiln::gl::bindImage(builder, "u_field", lampField_.id(), 0, false, GL_WRITE_ONLY, GL_RG16F);
        const GLuint groups = GLuint((side + 7) / 8);
        glDispatchCompute(groups, groups, 1);
        glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT);
        builtField_ = key;
        return true;
    }

    FieldKey builtField_;
    kiln::gl::Texture lampField_;

    // The pixels a sphere can cover: its bounding box's corners projected; the whole
    // output when one is behind the camera.
    static kiln::PixelRect screenRect(kiln::PassContext& ctx, glm::vec3 centre, float radius) {
        const int w = ctx.frame().outputWidth, h = ctx.frame().outputHeight;
        glm::vec2 lo(1.0f), hi(-1.0f);
        for (int i = 0; i < 8; ++i) {
            const glm::vec3 corner = centre + radius * glm::vec3(i & 1 ? 1 : -1, i & 2 ? 1 : -1, i & 4 ? 1 : -1);
            const glm::vec4 clip = ctx.scene().frame.viewProj * glm::vec4(corner, 1.0f);
            if (clip.w <= 1e-4f) return {0, 0, w, h};
            lo = glm::min(lo, glm::vec2(clip) / clip.w);
            hi = glm::max(hi, glm::vec2(clip) / clip.w);
        }
        lo = glm::clamp(lo, -1.0f, 1.0f), hi = glm::clamp(hi, -1.0f, 1.0f);
        const int x0 = int(std::floor((lo.x * 0.5f + 0.5f) * w)), y0 = int(std::floor((lo.y * 0.5f + 0.5f) * h));
        const int x1 = int(std::ceil((hi.x * 0.5f + 0.5f) * w)), y1 = int(std::ceil((hi.y * 0.5f + 0.5f) * h));
        return {x0, y0, std::max(0, x1 - x0), std::max(0, y1 - y0)};
    }

    kiln::gl::SamplerHandle compareSampler_;
    bool hdr_ = true;  // this run writes `hdr` (something reads it)
    float fittedGamma_ = -1.0f;  // what gammaFit_ is for
    kiln::GammaFit gammaFit_;

    // keep_direct (the pass's own objects: a reload starts over).
    // tile_lists.comp's buffer: two draw commands, the count of moved tiles at [8], the lists.
    static constexpr uint32_t kMovedCountAt = 8, kListsStart = 12;
    // The share of moved tiles above which the whole is drawn (on llvmpipe drawing in
    // tiles costs a fixed part plus one growing with the share, against the whole's
    // flat cost), and below which tiles come back.
    static constexpr double kTilesUpTo = 0.75, kTilesBackBelow = 0.6;
    static constexpr uint32_t kCountWholeEvery = 8;
    bool drawingWhole_ = false;
    uint32_t wholeRuns_ = 0;                // runs drawn whole in a row
    std::array<uint64_t, 3> instancesSeen_{};  // the followed categories' versions at the last run
    std::optional<CacheKey> cacheKey_;      // what the kept light was computed from; empty: nothing kept
    kiln::gl::Buffer previous_;             // the instances at the last run
    uint32_t previousEnd_ = 0;              // how many there were
    bool previousKept_ = false;
    kiln::gl::Buffer tileMarks_;            // one a tile: moved_tiles.comp marks, tile_lists.comp clears
    kiln::gl::Buffer tileLists_;            // two draw commands, the moved count, the two lists
    kiln::gl::TextureHandle tileListsTexture_;  // the same as a buffer texture (tiles.vert)
    kiln::gl::Buffer pyramids_;             // the moved casters' shadow pyramids (moved_tiles.comp)
    kiln::gl::Buffer movedCount_;           // the count copied out, read once the GPU is past it
    GLsync countFence_ = nullptr;
    uint32_t countedTiles_ = 0;
    double movedShare_ = 0.0;               // of the tiles at the last count read
    kiln::gl::VertexArrayHandle vertexArray_;
};

}  // namespace

KILN_PASS_MODULE(composite, Composite)
