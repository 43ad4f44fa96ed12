// lights — the shadow atlas of the scene's punctual lights (glTF KHR_lights_punctual):
// one depth tile per shadowed light (GpuFrame::punctual[i].color.w), drawn with the
// light's matrix (a directional light's orthographic view of the scene's bounds, a spot
// light's perspective over its cone). composite shades from it; a scene without
// shadowed lights leaves it untouched.
#include <kiln/pass.hpp>

namespace {

class Lights final : public kiln::Pass {
public:
    kiln::PassDeclaration declare() const override {
        using namespace kiln;
        PassDeclaration d;
        d.output({.name = "shadow_atlas", .kind = TextureKind::Depth2D, .format = Format::Depth32F,
                  .size = SizeRule::fromParam("shadow_size", 1.0f, kMaxShadowedLights),
                  .doc = "one square tile per shadowed punctual light, side by side along x (tile = "
                         "GpuPunctualLight::color.w), depth through its shadowViewProj"})
            .param(intChoiceParam("shadow_size", 1024, {256, 512, 1024, 2048}, "texels a side of each light's tile"))
            .param(floatParam("slope_bias", 2.0f, 0.0, 10.0, "polygon offset factor against shadow acne"));
        d.reads = kSceneStatic | kSceneMeshes | kSceneShadowCasters | kSceneLight;
        return d;
    }

    void execute(kiln::PassContext& ctx) override {
        const kiln::GpuFrame& f = ctx.scene().frame;
        int shadowed = 0;
        for (uint32_t i = 0; i < f.punctualCount.x; ++i) shadowed += f.punctual[i].color.w >= 0.0f ? 1 : 0;
        if (shadowed == 0) return ctx.nothingToDo("no shadowed punctual light in the scene");
        GLuint program = ctx.program({.stages = {"lights/shadow.vert", "shadow/shadow.frag"}});
        if (!program || !ctx.framebuffer({}, "shadow_atlas")) return;
        const float one = 1.0f;
        glClearBufferfv(GL_DEPTH, 0, &one);
        glEnable(GL_DEPTH_TEST);
        glDepthFunc(GL_LESS);
        glEnable(GL_POLYGON_OFFSET_FILL);
        glPolygonOffset(ctx.getFloat("slope_bias"), 4.0f);
        glUseProgram(program);
        const int side = ctx.getInt("shadow_size");
        for (uint32_t i = 0; i < f.punctualCount.x; ++i) {
            const int tile = int(f.punctual[i].color.w);
            if (tile < 0) continue;
            glViewport(tile * side, 0, side, side);
            glUniform1i(glGetUniformLocation(program, "u_light"), GLint(i));
            // Everything opaque casts: the walls and the dome too (a sun outside the box
            // is shut out by it). Emitters that do not cast (fireballs, particles) do not.
            ctx.drawScene({.categories = kiln::kSceneStatic | kiln::kSceneMeshes | kiln::kSceneShadowCasters,
                           .lod = kiln::Lod::Medium});
        }
    }
};

}  // namespace

KILN_PASS_MODULE(lights, Lights)
