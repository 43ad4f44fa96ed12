// bloom — the glow of bright emitters: a bright pass of the emitted radiance, then a
// separable Gaussian (radius 4 = the seed's 9×9) through two internal ping-pong
// textures at half resolution. Composite adds it before tonemapping.
#include <kiln/pass.hpp>

namespace {

class Bloom final : public kiln::Pass {
public:
    kiln::PassDeclaration declare() const override {
        using namespace kiln;
        PassDeclaration d;
        const SizeRule half = SizeRule::relative(0.5f);
        d.input({.name = "emissive", .doc = "emitted radiance (gbuffer.emissive)"})
            .output({.name = "bloom", .format = Format::RGBA16F, .size = half})
            .internal({.name = "ping", .format = Format::RGBA16F, .size = half})
            .internal({.name = "pong", .format = Format::RGBA16F, .size = half})
            .param(floatParam("threshold", 1.0f, 0.0, 50.0, "radiance above which a pixel blooms"))
            .param(intParam("radius", 4, 1, 16, "Gaussian taps each side: 4 = 9x9"))
            .param(floatParam("intensity", 0.5f, 0.0, 4.0))
            .shader("bloom/bright.frag")
            .shader("bloom/blur.frag");
        return d;
    }

    void execute(kiln::PassContext& ctx) override {
        GLuint bright = ctx.program({.stages = {"common/fullscreen.vert", "bloom/bright.frag"}});
        GLuint blur = ctx.program({.stages = {"common/fullscreen.vert", "bloom/blur.frag"}});
        if (!bright || !blur) return;
        if (!ctx.framebuffer({"ping"})) return;
        glUseProgram(bright);
        glBindTextureUnit(0, ctx.input("emissive").id);
        glUniform1f(glGetUniformLocation(bright, "u_threshold"), ctx.getFloat("threshold"));
        ctx.drawFullscreenTriangle();

        const kiln::TextureRef& ping = ctx.internal("ping");
        glUseProgram(blur);
        glUniform1i(glGetUniformLocation(blur, "u_radius"), ctx.getInt("radius"));
        auto pass = [&](const char* target, const char* source, float dx, float dy, float gain) {
            ctx.framebuffer({target});
            glBindTextureUnit(0, std::string(source) == "ping" ? ping.id : ctx.internal(source).id);
            glUniform2f(glGetUniformLocation(blur, "u_direction"), dx / float(ping.width), dy / float(ping.height));
            glUniform1f(glGetUniformLocation(blur, "u_gain"), gain);
            ctx.drawFullscreenTriangle();
        };
        pass("pong", "ping", 1.0f, 0.0f, 1.0f);
        // The last pass writes the output, scaled by the intensity.
        glBindFramebuffer(GL_FRAMEBUFFER, ctx.framebuffer({"bloom"}));
        glBindTextureUnit(0, ctx.internal("pong").id);
        glUniform2f(glGetUniformLocation(blur, "u_direction"), 0.0f, 1.0f / float(ping.height));
        glUniform1f(glGetUniformLocation(blur, "u_gain"), ctx.getFloat("intensity"));
        ctx.drawFullscreenTriangle();
    }
};

}  // namespace

KILN_PASS_MODULE(bloom, Bloom)
