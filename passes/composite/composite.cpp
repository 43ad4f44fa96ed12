// composite — the final image: direct light from the lamp (the cap emitter of
// shaders/common/light.glsl, `lamp_samples` quadrature points) on the G-buffer (5×5 PCF
// shadows from `shadow_map`), plus albedo × indirect irradiance (cone_trace), emission
// and bloom; tonemap and gamma. Bloom is computed before this pass from the G-buffer's
// emitted radiance (see passes/bloom), so no separate "lighting" pass is needed.
#include <kiln/pass.hpp>

namespace {

class Composite final : public kiln::Pass {
public:
    kiln::PassDeclaration declare() const override {
        using namespace kiln;
        PassDeclaration d;
        d.input({.name = "albedo"})
            .input({.name = "normal"})
            .input({.name = "depth", .kind = TextureKind::Depth2D})
            .input({.name = "emissive", .required = false, .fallback = Fallback::Black})
            .input({.name = "shadow_map", .kind = TextureKind::Depth2D, .required = false})
            .input({.name = "indirect", .required = false, .fallback = Fallback::Black})
            .input({.name = "bloom", .required = false, .fallback = Fallback::Black})
            .output({.name = "color", .format = Format::RGBA8, .doc = "tonemapped, gamma-encoded final image"})
            .output({.name = "hdr", .format = Format::RGBA16F, .doc = "linear radiance before bloom, exposure and tonemapping"})
            .param(floatParam("exposure", 1.0f, 0.01, 16.0, "scales radiance before tonemapping"))
            .param(floatParam("ambient", 0.03f, 0.0, 1.0, "constant fill light when no indirect input is bound"))
            .param(enumParam("tonemap", "aces", {"aces", "reinhard", "clamp"}))
            .param(floatParam("gamma", 2.2f, 1.0, 3.0))
            .param(intChoiceParam("pcf", 5, {1, 3, 5, 7, 9}, "shadow filter kernel side: 5 = the seed's 5x5, 1 = hard"))
            .param(floatParam("indirect_strength", 1.0f, 0.0, 8.0, "scales the bound indirect irradiance (1 = physical)"))
            .param(floatParam("shadow_bias", 0.0005f, 0.0, 0.05, "depth bias of the shadow test"))
            .param(intChoiceParam("lamp_samples", 32, {4, 8, 16, 32, 64},
                                  "quadrature points over the lamp's cap for its direct light"));
        d.reads = kSceneLight | kSceneCamera;
        return d;
    }

    void execute(kiln::PassContext& ctx) override {
        GLuint program = ctx.program({.stages = {"common/fullscreen.vert", "composite/composite.frag"},
                                      .defines = {{"KILN_LAMP_SAMPLES", std::to_string(ctx.getInt("lamp_samples"))}}});
        if (!program) return;
        if (!ctx.framebuffer({"color", "hdr"})) return;
        glUseProgram(program);
        const char* inputs[] = {"albedo", "normal", "depth", "emissive", "shadow_map", "indirect", "bloom"};
        for (GLuint unit = 0; unit < 7; ++unit) glBindTextureUnit(unit, ctx.input(inputs[unit]).id);
        const std::string& tonemap = ctx.getEnum("tonemap");
        glUniform1f(glGetUniformLocation(program, "u_exposure"), ctx.getFloat("exposure"));
        glUniform1f(glGetUniformLocation(program, "u_ambient"), ctx.getFloat("ambient"));
        glUniform1f(glGetUniformLocation(program, "u_gamma"), ctx.getFloat("gamma"));
        glUniform1i(glGetUniformLocation(program, "u_tonemap"), tonemap == "aces" ? 0 : tonemap == "reinhard" ? 1 : 2);
        glUniform1i(glGetUniformLocation(program, "u_pcf"), ctx.getInt("pcf"));
        glUniform1f(glGetUniformLocation(program, "u_shadowBias"), ctx.getFloat("shadow_bias"));
        glUniform1f(glGetUniformLocation(program, "u_indirectStrength"), ctx.getFloat("indirect_strength"));
        ctx.drawFullscreenTriangle();
    }
};

}  // namespace

KILN_PASS_MODULE(composite, Composite)
