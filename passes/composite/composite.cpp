// composite — the final image: direct light from the lamp (the cap emitter of
// shaders/common/light.glsl: its silhouette's contour integral, `lamp_samples`
// quadrature points, cone_trace's traced samples, or n · its vector irradiance from a
// grid this pass builds when the lamp changes) on the G-buffer (PCF or PCSS
// shadows from `shadow_map`), plus albedo × indirect irradiance (cone_trace), emission
// and bloom; tonemap and gamma. Bloom is computed before this pass from the G-buffer's
// emitted radiance (see passes/bloom), so no separate "lighting" pass is needed.
#include <kiln/pass.hpp>

#include <algorithm>
#include <cmath>
#include <string>

#include <glm/glm.hpp>

namespace {

class Composite final : public kiln::Pass {
public:
    kiln::PassDeclaration declare() const override {
        using namespace kiln;
        PassDeclaration d;
        // The G-buffer inputs are read texel for texel (the output's size); the indirect
        // light, the bloom and the shadow map are filtered lookups at any size.
        d.input({.name = "albedo", .doc = "output-sized"})
            .input({.name = "normal", .doc = "output-sized"})
            .input({.name = "depth", .kind = TextureKind::Depth2D, .doc = "output-sized"})
            .input({.name = "emissive", .required = false, .fallback = Fallback::Black, .doc = "output-sized"})
            .input({.name = "shadow_map", .kind = TextureKind::Depth2D, .required = false})
            .input({.name = "indirect", .required = false, .fallback = Fallback::Black})
            .input({.name = "bloom", .required = false, .fallback = Fallback::Black})
            .output({.name = "color", .format = Format::RGBA8, .doc = "tonemapped, gamma-encoded final image"})
            .output({.name = "hdr", .format = Format::RGBA16F, .doc = "linear radiance before bloom, exposure and tonemapping"})
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
                                  "vertices of the lamp's silhouette (contour) or quadrature points over its cap (points)"));
        d.reads = kSceneLight | kSceneCamera | kSceneFireballs;
        return d;
    }

    void execute(kiln::PassContext& ctx) override {
        const std::string& lampModel = ctx.getEnum("lamp_model");
        auto variant = [&](bool nearField) {
            return ctx.program({.stages = {"common/fullscreen.vert", "composite/composite.frag"},
                                .defines = {{"KILN_LAMP_SAMPLES", std::to_string(ctx.getInt("lamp_samples"))},
                                            {"KILN_LAMP_CONTOUR", lampModel == "points" ? "0" : "1"},
                                            {"KILN_LAMP_TRACED", lampModel == "traced" ? "1" : "0"},
                                            {"KILN_LAMP_FIELD", lampModel == "field" ? "1" : "0"},
                                            {"KILN_LAMP_NEAR_FIELD", nearField ? "1" : "0"},
                                            {"KILN_PCF", std::to_string(ctx.getInt("pcf"))},
                                            {"KILN_PCSS", ctx.getEnum("shadow_filter") == "pcss" ? "1" : "0"},
                                            {"KILN_LAMP_THROUGH_FIRE", ctx.getBool("lamp_through_fire") ? "1" : "0"},
                                            {"KILN_FIREBALLS_ANALYTIC", ctx.getEnum("fireball_light") == "analytic" ? "1" : "0"}}});
        };
        GLuint program = variant(false);
        if (!program) return;
        const bool nearField = (lampModel == "traced" || lampModel == "field") && ctx.getFloat("lamp_near_field") > 0.0f;
        if (lampModel == "field" && !buildLampField(ctx)) return;
        GLuint nearProgram = nearField ? variant(true) : 0;
        if (nearField && !nearProgram) return;
        if (lampModel == "traced" && ctx.getBool("lamp_through_fire"))
            return ctx.fail("lamp_model traced and lamp_through_fire both read `indirect`'s alpha (the lamp, or its "
                            "transmittance through the fire): pick one");
        if (ctx.getBool("lamp_through_fire") && !ctx.isBound("indirect"))
            return ctx.fail("lamp_through_fire reads the lamp's transmittance through the fire from `indirect` "
                            "(cone_trace.indirect with cone_trace's `lamp_transmittance` bound): bind it, or turn it off");
        if (lampModel == "traced" && !ctx.isBound("indirect"))
            return ctx.fail("lamp_model traced reads the lamp from `indirect` (cone_trace.indirect with cone_trace's "
                            "`lamp` on): bind it, or use lamp_model contour");
        if (!ctx.framebuffer({"color", "hdr"})) return;
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
        // Where only bodies moved, only what they change (kiln/pass.hpp).
        const kiln::TextureRef& color = ctx.output("color");
        kiln::forEachRedrawRect(ctx, color.width, color.height, 0, [&] { draw(ctx, program); });
        // The near field again, per pixel, over its screen rectangle only (within each
        // rectangle to redraw).
        if (nearField) {
            const glm::vec4 lamp = ctx.scene().frame.lightPos;
            const kiln::PixelRect r = screenRect(ctx, glm::vec3(lamp), lamp.w + ctx.getFloat("lamp_near_field"));
            glEnable(GL_SCISSOR_TEST);
            for (const kiln::PixelRect& part : kiln::redrawRects(ctx, color.width, color.height, 0)) {
                const int x0 = std::max(r.x, part.x), x1 = std::min(r.x + r.width, part.x + part.width);
                const int y0 = std::max(r.y, part.y), y1 = std::min(r.y + r.height, part.y + part.height);
                if (x1 <= x0 || y1 <= y0) continue;
                glScissor(x0, y0, x1 - x0, y1 - y0);
                draw(ctx, nearProgram);
            }
            glDisable(GL_SCISSOR_TEST);
        }
        kiln::gl::bindSamplerObject(program, "u_shadowMap", 0);  // the host resets textures, not samplers
    }

private:
    void draw(kiln::PassContext& ctx, GLuint program) const {
        glUseProgram(program);
        // Each input to the sampler of its name (u_shadow_map is u_shadowMap).
        for (auto [slot, sampler] : {std::pair{"albedo", "u_albedo"}, {"normal", "u_normal"}, {"depth", "u_depth"},
                                     {"emissive", "u_emissive"}, {"shadow_map", "u_shadowMap"},
                                     {"indirect", "u_indirect"}, {"bloom", "u_bloom"}})
            kiln::gl::bindTexture(program, sampler, ctx.input(slot).id);
        kiln::gl::bindSamplerObject(program, "u_shadowMap", compareSampler_.id());
        kiln::gl::bindTexture(program, "u_shadowDepth", ctx.input("shadow_map").id);  // pcss only
        kiln::gl::bindTexture(program, "u_lampField", lampField_.id());  // field only
        const std::string& tonemap = ctx.getEnum("tonemap");
        glUniform1f(glGetUniformLocation(program, "u_exposure"), ctx.getFloat("exposure"));
        glUniform1f(glGetUniformLocation(program, "u_ambient"), ctx.getFloat("ambient"));
        glUniform1f(glGetUniformLocation(program, "u_gamma"), ctx.getFloat("gamma"));
        glUniform1i(glGetUniformLocation(program, "u_tonemap"), tonemap == "aces" ? 0 : tonemap == "reinhard" ? 1 : 2);
        glUniform1f(glGetUniformLocation(program, "u_shadowBias"), ctx.getFloat("shadow_bias"));
        glUniform1f(glGetUniformLocation(program, "u_indirectStrength"), ctx.getFloat("indirect_strength"));
        glUniform1f(glGetUniformLocation(program, "u_lampNearField"), ctx.getFloat("lamp_near_field"));
        glUniform1i(glGetUniformLocation(program, "u_firstFireball"), int(ctx.scene().firstInstance(kiln::kSceneFireballs)));
        glUniform1i(glGetUniformLocation(program, "u_fireballCount"), int(ctx.scene().count(kiln::kSceneFireballs)));
        ctx.drawFullscreenTriangle();
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
        const FieldKey key{ctx.scene().version(kiln::kSceneLight), side, builder};
        if (key == builtField_) return true;
        glUseProgram(builder);
        kiln::gl::bindImage(builder, "u_field", lampField_.id(), 0, false, GL_WRITE_ONLY, GL_RG16F);
        const GLuint groups = GLuint((side + 7) / 8);
        glDispatchCompute(groups, groups, 1);
        glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT);
        builtField_ = key;
        return true;
    }

    struct FieldKey {
        uint64_t lightVersion = 0;
        int side = 0;
        GLuint program = 0;
        bool operator==(const FieldKey&) const = default;
    };
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
};

}  // namespace

KILN_PASS_MODULE(composite, Composite)
