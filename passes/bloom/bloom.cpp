// bloom — the bright part of the picture, blurred: a bright-pass of the
// G-buffer's emitted radiance (`color`, bound to gbuffer.emissive), then a separable
// Gaussian of σ = radius/2 full-resolution pixels (radius 4 = the course design's 9×9 kernel).
// It runs at HALF resolution: a compute bright-pass keeps the part above the threshold
// of each 2×2 block's mean in the internal `bright` (a quarter of the pixels), and the blur uses
// radius/2 taps per side with σ halved, so the glow has the course design's footprint on
// screen; composite's bilinear lookup upsamples it. Horizontal into the internal
// `ping`, vertical into `bloom`. Composite adds it.
//
// Order: bloom runs BEFORE composite, so it cannot read composite's HDR image. What
// blooms in this scene is what glows — the lamp, the fireballs, the particles, burning
// marbles — and that is exactly the emitted radiance, so the bright-pass reads it (the
// course design's "bright part of the G-buffer colour"); direct-lit surfaces stay around 1 and
// would not pass a threshold of 1 anyway. No lighting/composite split is needed.
//
// Nothing bright: the bright-pass also raises a flag in a 4-byte buffer (an atomicOr
// from each block with a texel above the threshold) that the blur's vertex shader
// reads; with the flag down it draws nothing over the targets cleared to black. The
// flag never comes back to the CPU: a read-back right after the dispatch would stall
// the CPU on the GPU every frame.
#include <kiln/pass.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>

namespace {

class Bloom final : public kiln::Pass {
public:
    kiln::PassDeclaration declare() const override {
        using namespace kiln;
        PassDeclaration d;
        d.input({.name = "color", .doc = "what may glow: gbuffer.emissive"})
            .output({.name = "bloom", .format = Format::RGBA16F, .size = SizeRule::relative(0.5f),
                     .doc = "blurred bright part (half resolution), added by composite"})
            .internal({.name = "bright", .format = Format::RGBA16F, .size = SizeRule::relative(0.5f),
                       .doc = "bright-pass: the part of each 2×2 block's mean above the threshold"})
            .internal({.name = "ping", .format = Format::RGBA16F, .size = SizeRule::relative(0.5f),
                       .doc = "horizontal blur"})
            .param(floatParam("threshold", 1.0f, 0.0, 64.0, "luminance below which nothing blooms"))
            .param(intParam("radius", 4, 1, 16, "blur radius in pixels: taps = 2·radius+1 per axis (4 = 9×9)"))
            .param(floatParam("intensity", 0.6f, 0.0, 8.0, "scales the blurred light"))
            .param(enumParam("bright_stores", "auto", {"auto", "sparse", "dense"},
                             "how the bright-pass leaves its dark texels black (the same picture either way): "
                             "sparse clears its texture and stores only the bright texels (cheaper on "
                             "a CPU rasterizer); dense stores every texel and clears nothing (cheaper "
                             "on a GPU, where a cleared texture written by a shader costs more than "
                             "the writes); "
                             "auto: sparse on a CPU rasterizer (llvmpipe, softpipe), dense on anything else"));
        return d;
    }

    void execute(kiln::PassContext& ctx) override {
        const std::string& stores = ctx.getEnum("bright_stores");
        const bool sparse = stores == "sparse" || (stores == "auto" && cpuRasterizer());
        GLuint brightPass =
            ctx.program({.stages = {"bloom/bright.comp"}, .defines = {{"KILN_BRIGHT_SPARSE", sparse ? "1" : "0"}}});
        const int taps = (ctx.getInt("radius") + 1) / 2;  // per side, at half resolution
        GLuint blur = ctx.program({.stages = {"bloom/blur.vert", "bloom/blur.frag"},
                                   .defines = {{"KILN_BLUR_RADIUS", std::to_string(taps)}}});
        if (!brightPass || !blur) return;
        const kiln::TextureRef& in = ctx.input("color");
        const kiln::TextureRef& bright = ctx.internal("bright");
        const float threshold = ctx.getFloat("threshold");

        // 1. Bright-pass + downsample, and the "anything bright" flag for the blur's early out.
        if (!anyBright_) anyBright_ = kiln::gl::Buffer::create(20, nullptr, GL_DYNAMIC_STORAGE_BIT, "bloom.any_bright");
        const GLuint none[5] = {0, ~0u, ~0u, 0, 0};  // the flag; the bright texels' rectangle, empty
        glNamedBufferSubData(anyBright_.id(), 0, sizeof none, none);
        glUseProgram(brightPass);
        glUniform1f(glGetUniformLocation(brightPass, "u_threshold"), threshold);
        kiln::gl::bindTexture(brightPass, "u_color", in.id);
        kiln::gl::bindImage(brightPass, "u_bright", bright.id, 0, false, GL_WRITE_ONLY, GL_RGBA16F);
        kiln::gl::bindStorageBuffer(brightPass, "AnyBright", anyBright_.id());
        // Where only bodies moved, only what they change (kiln/pass.hpp): the vertical
        // blur reads `ping` `taps` texels up and down, which read `bright` `taps` left and
        // right, so each stage covers the next one's rectangles grown by `taps` (and the
        // flag sees every texel the blur reads); `bloom` one texel spare for composite's
        // filtered read. Sparse, the bright-pass stores only the bright texels
        // (bloom/bright.comp), so each rectangle is cleared first.
        const float black[4] = {0.0f, 0.0f, 0.0f, 1.0f};
        for (const kiln::PixelRect& r : kiln::redrawRects(ctx, bright.width, bright.height, 2 * taps + 1)) {
            if (sparse) glClearTexSubImage(bright.id, 0, r.x, r.y, 0, r.width, r.height, 1, GL_RGBA, GL_FLOAT, black);
            glUniform2i(glGetUniformLocation(brightPass, "u_origin"), r.x, r.y);
            glDispatchCompute(GLuint((r.width + 7) / 8), GLuint((r.height + 7) / 8), 1);
        }
        glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_TEXTURE_FETCH_BARRIER_BIT);

        // 2. Horizontal blur → ping; vertical → bloom.
        glUseProgram(blur);
        // Gaussian weights of σ = radius/4 half-resolution pixels (radius/2 full ones), normalised.
        const float sigma = std::max(0.5f, float(ctx.getInt("radius")) * 0.25f);
        float weights[9] = {};
        float total = 0.0f;
        for (int i = 0; i <= taps; ++i) {
            weights[i] = std::exp(-float(i * i) / (2.0f * sigma * sigma));
            total += i == 0 ? weights[i] : 2.0f * weights[i];  // taps ±i share a weight
        }
        for (int i = 0; i <= taps; ++i) weights[i] /= total;
        glUniform1fv(glGetUniformLocation(blur, "u_weights"), taps + 1, weights);
        // Black where nothing is drawn (blur.vert collapses the triangle when nothing is bright).
        if (!ctx.framebuffer({"ping"})) return;
        glUniform2f(glGetUniformLocation(blur, "u_direction"), 1.0f, 0.0f);
        glUniform1f(glGetUniformLocation(blur, "u_gain"), 1.0f);
        kiln::gl::bindStorageBuffer(blur, "AnyBright", anyBright_.id());
        kiln::gl::bindTexture(blur, "u_src", bright.id);
        glUniform2f(glGetUniformLocation(blur, "u_targetSize"), float(bright.width), float(bright.height));
        if (!rectangleVao_) rectangleVao_ = kiln::gl::createVertexArray();
        glBindVertexArray(rectangleVao_.id());
        kiln::forEachRedrawRect(ctx, bright.width, bright.height, taps + 1, [&] {
            glClearBufferfv(GL_COLOR, 0, black);
            glDrawArrays(GL_TRIANGLES, 0, 6);  // round the bright texels (bloom/blur.vert)
        });
        if (!ctx.framebuffer({"bloom"})) return;
        glUniform2f(glGetUniformLocation(blur, "u_direction"), 0.0f, 1.0f);
        glUniform1f(glGetUniformLocation(blur, "u_gain"), ctx.getFloat("intensity"));
        kiln::gl::bindTexture(blur, "u_src", ctx.internal("ping").id);
        kiln::forEachRedrawRect(ctx, bright.width, bright.height, 1, [&] {
            glClearBufferfv(GL_COLOR, 0, black);
            glDrawArrays(GL_TRIANGLES, 0, 6);
        });
        glBindVertexArray(0);
    }

private:
    // Mesa's CPU rasterizers, by the renderer's name: they skip a masked lane's store
    // and clear a texture cheaply; a GPU is the other way round (bright_stores).
    static bool cpuRasterizer() {
        static const bool cpu = [] {
            const char* renderer = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
            return renderer && (std::strstr(renderer, "llvmpipe") || std::strstr(renderer, "softpipe"));
        }();
        return cpu;
    }

    kiln::gl::Buffer anyBright_;  // nonzero when a texel passed the threshold, and their rectangle; GPU only
    kiln::gl::VertexArrayHandle rectangleVao_;  // attribute-less: blur.vert makes the rectangle
};

}  // namespace

KILN_PASS_MODULE(bloom, Bloom)
