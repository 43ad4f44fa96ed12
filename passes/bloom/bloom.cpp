// bloom — the bright part of the picture, blurred (SPEC §6.5): a bright-pass of the
// G-buffer's emitted radiance (`color`, bound to gbuffer.emissive), then a separable
// Gaussian of σ = radius/2 full-resolution pixels (radius 4 = the seed's 9×9 kernel).
// It runs at HALF resolution: the bright-pass averages each 2×2 block (the same light,
// a quarter of the pixels) and the blur uses radius/2 taps per side with σ halved, so
// the glow has the seed's footprint on screen at about 1/8 of the full-resolution
// cost; composite's bilinear lookup upsamples it. Horizontal into the internal
// ping-pong texture, vertical into `bloom`. Composite adds it.
//
// Order: bloom runs BEFORE composite, so it cannot read composite's HDR image. What
// blooms in this scene is what glows — the lamp, the fireballs, the particles, burning
// marbles — and that is exactly the emitted radiance, so the bright-pass reads it (the
// seed's "bright part of the G-buffer colour"); direct-lit surfaces stay around 1 and
// would not pass a threshold of 1 anyway. No lighting/composite split is needed.
//
// Nothing bright: a small compute reduction first finds the brightest luminance of the
// input (one atomicMax per 8×8 group of 4×4 texel tiles) into a 4-byte buffer that the
// blur reads; below the threshold every blur fragment writes black without a single
// tap. The value never comes back to the CPU: a read-back right after the dispatch
// would stall the CPU on the GPU every frame.
#include <kiln/pass.hpp>

#include <algorithm>
#include <cmath>
#include <string>

namespace {

class Bloom final : public kiln::Pass {
public:
    ~Bloom() override {
        if (maxBuffer_) glDeleteBuffers(1, &maxBuffer_);
    }

    kiln::PassDeclaration declare() const override {
        using namespace kiln;
        PassDeclaration d;
        d.input({.name = "color", .doc = "what may glow: gbuffer.emissive"})
            .output({.name = "bloom", .format = Format::RGBA16F, .size = SizeRule::relative(0.5f),
                     .doc = "blurred bright part (half resolution), added by composite"})
            .internal({.name = "ping", .format = Format::RGBA16F, .size = SizeRule::relative(0.5f),
                       .doc = "bright-pass + horizontal blur"})
            .param(floatParam("threshold", 1.0f, 0.0, 64.0, "luminance below which nothing blooms"))
            .param(intParam("radius", 4, 1, 16, "blur radius in pixels: taps = 2·radius+1 per axis (4 = 9×9)"))
            .param(floatParam("intensity", 0.6f, 0.0, 8.0, "scales the blurred light"));
        return d;
    }

    void execute(kiln::PassContext& ctx) override {
        GLuint reduce = ctx.program({.stages = {"bloom/max.comp"}});
        GLuint blur = ctx.program({.stages = {"common/fullscreen.vert", "bloom/blur.frag"}});
        if (!reduce || !blur) return;
        const kiln::TextureRef& in = ctx.input("color");
        const float threshold = ctx.getFloat("threshold");

        // 1. The brightest luminance, for the blur's early out.
        if (!maxBuffer_) {
            glCreateBuffers(1, &maxBuffer_);
            glNamedBufferStorage(maxBuffer_, 4, nullptr, GL_DYNAMIC_STORAGE_BIT);
        }
        const GLuint zero = 0;
        glNamedBufferSubData(maxBuffer_, 0, 4, &zero);
        glUseProgram(reduce);
        glBindTextureUnit(0, in.id);
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, maxBuffer_);
        glDispatchCompute(GLuint((in.width + 31) / 32), GLuint((in.height + 31) / 32), 1);
        glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);

        // 2. Bright-pass + horizontal blur → ping; vertical blur → bloom.
        glUseProgram(blur);
        glUniform1i(glGetUniformLocation(blur, "u_radius"), (ctx.getInt("radius") + 1) / 2);
        glUniform1f(glGetUniformLocation(blur, "u_sigma"), std::max(0.5f, float(ctx.getInt("radius")) * 0.25f));
        glUniform1f(glGetUniformLocation(blur, "u_threshold"), threshold);
        if (!ctx.framebuffer({"ping"})) return;
        glUniform2f(glGetUniformLocation(blur, "u_direction"), 1.0f, 0.0f);
        glUniform1f(glGetUniformLocation(blur, "u_gain"), 1.0f);
        glUniform1i(glGetUniformLocation(blur, "u_brightPass"), 1);
        glBindTextureUnit(0, in.id);
        ctx.drawFullscreenTriangle();
        if (!ctx.framebuffer({"bloom"})) return;
        glUniform2f(glGetUniformLocation(blur, "u_direction"), 0.0f, 1.0f);
        glUniform1f(glGetUniformLocation(blur, "u_gain"), ctx.getFloat("intensity"));
        glUniform1i(glGetUniformLocation(blur, "u_brightPass"), 0);
        glBindTextureUnit(0, ctx.internal("ping").id);
        ctx.drawFullscreenTriangle();
    }

private:
    GLuint maxBuffer_ = 0;  // 4 bytes: the brightest luminance (float bits), GPU only
};

}  // namespace

KILN_PASS_MODULE(bloom, Bloom)
