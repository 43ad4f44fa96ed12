// error — an image against a reference, made visible: a false-colour map of the
// per-pixel relative squared error (I − R)² / (R² + ε), ε = 0.01 (the relative MSE of
// host/metrics, per pixel) on a log scale from 10^−4 (black) through blue, green and
// yellow to 1 and beyond (white); or the signed difference (red: too bright, blue: too
// dark), or a split screen (image left of `split`, reference right, both tonemapped).
// A legend of the colour map runs along the bottom (`legend`).
// The numbers themselves come from kiln-bench-quality.
#include <kiln/pass.hpp>

#include <algorithm>
#include <cmath>

namespace {

class Error final : public kiln::Pass {
public:
    kiln::PassDeclaration declare() const override {
        using namespace kiln;
        PassDeclaration d;
        d.input({.name = "image", .doc = "linear radiance, e.g. composite.hdr"})
            .input({.name = "reference", .doc = "linear radiance, e.g. reference.radiance"})
            .output({.name = "color", .format = Format::RGBA8})
            .param(enumParam("mode", "relative", {"relative", "signed", "split"},
                             "false-colour relative error, signed difference, or side by side"))
            .param(floatParam("scale", 1.0f, 0.01, 100.0, "signed mode: the difference shown at full colour"))
            .param(floatParam("split", 0.5f, 0.0, 1.0, "split mode: where the reference starts (fraction of the width)"))
            .param(boolParam("legend", true,
                             "a strip along the bottom with the colour map: relative 10^-4 to 1 with a tick per decade, "
                             "signed -scale to +scale with a tick at 0 (the window labels it)"));
        return d;
    }

    void execute(kiln::PassContext& ctx) override {
        GLuint program = ctx.program({.stages = {"common/fullscreen.vert", "error/error.frag"}});
        if (!program || !ctx.framebuffer({"color"})) return;
        glUseProgram(program);
        kiln::gl::bindTexture(program, "u_image", ctx.input("image").id);
        kiln::gl::bindTexture(program, "u_reference", ctx.input("reference").id);
        const std::string& mode = ctx.getEnum("mode");
        glUniform1i(glGetUniformLocation(program, "u_mode"), mode == "relative" ? 0 : mode == "signed" ? 1 : 2);
        glUniform1f(glGetUniformLocation(program, "u_scale"), ctx.getFloat("scale"));
        glUniform1f(glGetUniformLocation(program, "u_split"), ctx.getFloat("split"));
        // At least 16 px, so the window's labels fit inside it.
        const float strip = ctx.getBool("legend") ? std::max(16.0f, std::floor(0.05f * float(ctx.frame().outputHeight))) : 0.0f;
        glUniform1f(glGetUniformLocation(program, "u_legendPx"), strip);
        ctx.drawFullscreenTriangle();
    }
};

}  // namespace

KILN_PASS_MODULE(error, Error)
