// lights — the shadow atlas of the scene's punctual lights (glTF KHR_lights_punctual):
// one depth tile per shadowed light (GpuFrame::punctual[i].color.w), drawn with the
// light's matrix (a directional light's orthographic view of the scene's bounds, a spot
// light's perspective over its cone). composite and voxelize shade from it; a scene
// without shadowed lights leaves it untouched.
#include <array>

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
        d.reads = kSceneStatic | kSceneMeshes | kSceneShadowCasters | kSceneLights;
        return d;
    }

    void execute(kiln::PassContext& ctx) override {
        const kiln::GpuFrame& f = ctx.scene().frame;
        int shadowed = 0;
        for (uint32_t i = 0; i < f.punctualCount.x; ++i) shadowed += f.punctual[i].color.w >= 0.0f ? 1 : 0;
        if (shadowed == 0) return ctx.nothingToDo("no shadowed punctual light in the scene");
        GLuint program = ctx.program({.stages = {"lights/shadow.vert", "shadow/shadow.frag"}});
        if (!program || !drawStatic(ctx, program) || !ctx.framebuffer({}, "shadow_atlas")) return;
        // What does not move (the walls, the dome, the placed meshes) is drawn once into
        // the pass's own atlas (again when it, a light, the size or the program change)
        // and copied under the moving casters each run.
        const kiln::TextureRef& atlas = ctx.output("shadow_atlas");
        glCopyImageSubData(staticAtlas_.id(), GL_TEXTURE_2D, 0, 0, 0, 0, atlas.id, GL_TEXTURE_2D, 0, 0, 0, 0,
                           atlas.width, atlas.height, 1);
        if (ctx.scene().count(kiln::kSceneShadowCasters) > 0)
            drawTiles(ctx, program, kiln::kSceneShadowCasters);
    }

private:
    // Each shadowed light's tile of the bound framebuffer: `categories` through its matrix.
    static void drawTiles(kiln::PassContext& ctx, GLuint program, uint32_t categories) {
        const kiln::GpuFrame& f = ctx.scene().frame;
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
            ctx.drawScene({.categories = categories, .lod = kiln::Lod::Medium});
        }
    }

    // The static casters' atlas, when what it depends on changed; false when the pass failed.
    bool drawStatic(kiln::PassContext& ctx, GLuint program) {
        const kiln::SceneView& scene = ctx.scene();
        const int side = ctx.getInt("shadow_size");
        const bool meshes = scene.count(kiln::kSceneMeshes) > 0;
        const GLuint cutout =
            meshes ? ctx.program({.stages = {"shadow/cutout.vert", "shadow/cutout.frag"},
                                  .defines = {{"KILN_PUNCTUAL_LIGHT", "1"},
                                              {"KILN_HAS_COLOR_LAYERS", scene.materialTextures[0] ? "1" : "0"}}})
                   : 0;
        if (meshes && !cutout) return false;
        const StaticKey key{{scene.version(kiln::kScenePlanes), scene.version(kiln::kSceneLightSurface),
                             scene.version(kiln::kSceneMeshes), scene.version(kiln::kSceneLights)},
                            program, cutout, side, ctx.getFloat("slope_bias"), scene.materialTextures[0]};
        if (key == built_ && staticAtlas_) return true;
        if (!staticAtlas_ || !framebuffer_ || staticAtlas_.height() != side) {
            staticAtlas_ = kiln::gl::Texture::create(GL_TEXTURE_2D, GL_DEPTH_COMPONENT32F, side * kiln::kMaxShadowedLights,
                                                     side, 1, 1, "lights.static_atlas");
            framebuffer_ = kiln::gl::createDepthFramebuffer(staticAtlas_.id());
            if (!framebuffer_) {
                ctx.fail("the static casters' atlas is incomplete as a framebuffer");
                return false;
            }
        }
        glBindFramebuffer(GL_FRAMEBUFFER, framebuffer_.id());
        const float one = 1.0f;
        glClearBufferfv(GL_DEPTH, 0, &one);
        // Everything opaque that stays casts: the walls and the dome too (a sun outside
        // the box is shut out by it), and the placed meshes with their cut-outs cut.
        drawTiles(ctx, program, kiln::kSceneStatic);
        if (meshes) {
            kiln::gl::bindTexture(cutout, "u_colorLayers", scene.materialTextures[0]);
            drawTiles(ctx, cutout, kiln::kSceneMeshes);
        }
        built_ = key;
        return true;
    }

    struct StaticKey {
        std::array<uint64_t, 4> versions{};  // box, lamp, meshes, light
        GLuint program = 0, cutout = 0;
        int side = 0;
        float slopeBias = -1.0f;
        uint32_t textures = 0;
        bool operator==(const StaticKey&) const = default;
    };
    // A cache (a module reload starts over): what staticAtlas_ was drawn from.
    StaticKey built_;
    kiln::gl::Texture staticAtlas_;
    kiln::gl::FramebufferHandle framebuffer_;
};

}  // namespace

KILN_PASS_MODULE(lights, Lights)
