// shadow — depth of the shadow casters (tumblers, marbles; fireballs emit, they don't
// cast) seen from the lamp, one perspective 2D map (projection in common/light.glsl).
// The host skips it unless bodies or the light changed; among body changes it also
// skips itself when no caster moved (a flying fireball alone changes nothing here).
#include <kiln/pass.hpp>

namespace {

class Shadow final : public kiln::Pass {
public:
    kiln::PassDeclaration declare() const override {
        using namespace kiln;
        PassDeclaration d;
        d.output({.name = "depth", .kind = TextureKind::Depth2D, .format = Format::Depth32F,
                  .size = SizeRule::fromParam("size"), .doc = "depth from the lamp; see common/light.glsl"})
            .param(intChoiceParam("size", 2048, {256, 512, 1024, 2048, 4096}, "shadow map side in texels"))
            .param(floatParam("slope_bias", 2.0f, 0.0, 10.0, "polygon offset factor against shadow acne"))
            .shader("shadow/shadow.vert")
            .shader("shadow/shadow.frag");
        d.reads = kSceneBodies | kSceneLight;
        return d;
    }

    void execute(kiln::PassContext& ctx) override {
        const kiln::SceneView& scene = ctx.scene();
        // The casters' contents (and the light, and our own output size) decide.
        const uint64_t key[4] = {scene.drawVersion(kiln::kDrawTumblers), scene.drawVersion(kiln::kDrawMarbles),
                                 scene.version(kiln::kSceneLight), uint64_t(ctx.output("depth").width)};
        if (ran_ && std::equal(key, key + 4, lastKey_)) {
            ctx.nothingToDo("no shadow caster moved");
            return;
        }
        // No caster at all: clear the map once (everything lit), then there is nothing
        // to draw until one appears.
        const bool empty = scene.count(kiln::kDrawTumblers) + scene.count(kiln::kDrawMarbles) == 0;
        if (empty && clearedEmpty_ && ctx.output("depth").width == int(lastKey_[3])) {
            ctx.nothingToDo("no casters");
            return;
        }
        GLuint program = ctx.program({.stages = {"shadow/shadow.vert", "shadow/shadow.frag"}});
        if (!program || !ctx.framebuffer({}, "depth")) return;
        const float one = 1.0f;
        glClearBufferfv(GL_DEPTH, 0, &one);
        glEnable(GL_DEPTH_TEST);
        glDepthFunc(GL_LESS);
        glEnable(GL_POLYGON_OFFSET_FILL);
        glPolygonOffset(ctx.getFloat("slope_bias"), 4.0f);
        glUseProgram(program);
        clearedEmpty_ = empty;
        if (!empty) ctx.drawScene({.categories = kiln::kDrawShadowCasters, .lod = kiln::Lod::High});
        glDisable(GL_POLYGON_OFFSET_FILL);
        std::copy(key, key + 4, lastKey_);
        ran_ = true;
    }

private:
    // A cache key only: losing it on a module reload just re-renders the map once.
    uint64_t lastKey_[4] = {};
    bool ran_ = false;
    bool clearedEmpty_ = false;  // the map holds the cleared "no casters" state
};

}  // namespace

KILN_PASS_MODULE(shadow, Shadow)
