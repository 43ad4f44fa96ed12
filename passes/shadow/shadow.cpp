// shadow — depth of the shadow casters (tumblers, marbles; fireballs emit, they don't
// cast) seen from the lamp, one perspective 2D map (projection in common/shadow.glsl).
// It reads only the casters and the light, so the host skips it while they are still
// (a flying fireball alone changes nothing here).
#include <kiln/pass.hpp>

namespace {

class Shadow final : public kiln::Pass {
public:
    kiln::PassDeclaration declare() const override {
        using namespace kiln;
        PassDeclaration d;
        d.output({.name = "depth", .kind = TextureKind::Depth2D, .format = Format::Depth32F,
                  .size = SizeRule::fromParam("size"), .doc = "depth from the lamp; see common/shadow.glsl",
                  .depthNear = 0.05f, .depthFar = 3.5f})  // shadow.glsl kLightNear, kLightFar
            .param(intChoiceParam("size", 2048, {256, 512, 1024, 2048, 4096}, "shadow map side in texels"))
            .param(floatParam("slope_bias", 2.0f, 0.0, 10.0, "polygon offset factor against shadow acne"));
        d.reads = kSceneShadowCasters | kSceneLight;
        return d;
    }

    void execute(kiln::PassContext& ctx) override {
        GLuint program = ctx.program({.stages = {"shadow/shadow.vert", "shadow/shadow.frag"}});
        if (!program || !ctx.framebuffer({}, "depth")) return;
        const float one = 1.0f;
        glClearBufferfv(GL_DEPTH, 0, &one);
        // No caster: the cleared map (everything lit) is the answer.
        if (ctx.scene().count(kiln::kSceneShadowCasters) == 0) return;
        glEnable(GL_DEPTH_TEST);
        glDepthFunc(GL_LESS);
        glEnable(GL_POLYGON_OFFSET_FILL);
        glPolygonOffset(ctx.getFloat("slope_bias"), 4.0f);
        glUseProgram(program);
        ctx.drawScene({.categories = kiln::kSceneShadowCasters, .lod = kiln::Lod::High});
    }
};

}  // namespace

KILN_PASS_MODULE(shadow, Shadow)
