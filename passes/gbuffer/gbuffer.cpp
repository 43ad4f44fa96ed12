// gbuffer — draws every mesh of the scene into albedo, world-space normal, emitted
// radiance and depth. The first pass of every pipeline.
#include <kiln/pass.hpp>

namespace {

class GBuffer final : public kiln::Pass {
public:
    kiln::PassDeclaration declare() const override {
        using namespace kiln;
        PassDeclaration d;
        d.output({.name = "albedo", .format = Format::RGBA8, .doc = "linear albedo"})
            .output({.name = "normal", .format = Format::RGBA16F, .doc = "world-space unit normal; w = 1 on geometry"})
            .output({.name = "emissive", .format = Format::RGBA16F, .doc = "emitted radiance"})
            .output({.name = "depth", .kind = TextureKind::Depth2D, .format = Format::Depth32F,
                     .depthNear = kCameraNear, .depthFar = kCameraFar})
            .param(boolParam("particles", true, "draw the particles"));
        d.reads = kSceneStatic | kSceneBodies | kSceneParticles | kSceneCamera;
        return d;
    }

    void execute(kiln::PassContext& ctx) override {
        GLuint program = ctx.program({.stages = {"gbuffer/gbuffer.vert", "gbuffer/gbuffer.frag"}});
        if (!program) return;
        if (!ctx.framebuffer({"albedo", "normal", "emissive"}, "depth")) return;
        const float zero[4] = {0, 0, 0, 0}, one = 1.0f;
        for (int i = 0; i < 3; ++i) glClearBufferfv(GL_COLOR, i, zero);
        glClearBufferfv(GL_DEPTH, 0, &one);
        glEnable(GL_DEPTH_TEST);
        glDepthFunc(GL_LESS);
        glUseProgram(program);
        kiln::DrawFilter filter;
        filter.categories = kiln::kSceneGeometry;
        if (!ctx.getBool("particles")) filter.categories &= ~kiln::kSceneParticles;
        ctx.drawScene(filter);
    }
};

}  // namespace

KILN_PASS_MODULE(gbuffer, GBuffer)
