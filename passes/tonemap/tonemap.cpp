// tonemap — an HDR image to the display: exposure, a curve (shaders/common/tonemap.glsl,
// the same as composite's) and gamma. Shows a radiance image that has no composite of
// its own, e.g. the path-traced reference (pipelines/reference.json).
#include <kiln/pass.hpp>

namespace {

class Tonemap final : public kiln::Pass {
public:
    kiln::PassDeclaration declare() const override {
        using namespace kiln;
        PassDeclaration d;
        d.input({.name = "hdr", .doc = "linear radiance"})
            .input({.name = "bloom", .required = false, .fallback = Fallback::Black, .doc = "added before exposure"})
            .output({.name = "color", .format = Format::RGBA8})
            .param(floatParam("exposure", 1.0f, 0.01, 16.0, "scales radiance before tonemapping"))
            .param(enumParam("tonemap", "aces", {"aces", "reinhard", "clamp"}))
            .param(floatParam("gamma", 2.2f, 1.0, 3.0));
        return d;
    }

    void execute(kiln::PassContext& ctx) override {
        GLuint program = ctx.program({.stages = {"common/fullscreen.vert", "tonemap/tonemap.frag"}});
        if (!program || !ctx.framebuffer({"color"})) return;
        glUseProgram(program);
        kiln::gl::bindTexture(program, "u_hdr", ctx.input("hdr").id);
        kiln::gl::bindTexture(program, "u_bloom", ctx.input("bloom").id);
        const std::string& curve = ctx.getEnum("tonemap");
        glUniform1f(glGetUniformLocation(program, "u_exposure"), ctx.getFloat("exposure"));
        glUniform1f(glGetUniformLocation(program, "u_gamma"), ctx.getFloat("gamma"));
        glUniform1i(glGetUniformLocation(program, "u_tonemap"), curve == "aces" ? 0 : curve == "reinhard" ? 1 : 2);
        ctx.drawFullscreenTriangle();
    }
};

}  // namespace

KILN_PASS_MODULE(tonemap, Tonemap)
