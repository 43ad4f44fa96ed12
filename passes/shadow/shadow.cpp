// shadow — depth of the shadow casters (tumblers, marbles and the placed meshes;
// fireballs emit, they don't cast) seen from the lamp, one perspective 2D map
// (projection in common/shadow.glsl).
// It reads only the casters and the light, so the host skips it while they are still
// (a flying fireball alone changes nothing here).
#include <kiln/pass.hpp>

namespace {

// The map resolves the casters no better than its texels: over its 140° a 512² map has
// 93 texels per metre at a metre from the lamp, so a tumbler (lower radius 0.2) 1.5 m
// below it spans a radius of 12 texels, where its mesh strays from the round cone by
// r·(1 − cos(π/n)): 0.03 of a texel at 48 slices, 0.1 at 24, 0.4 at 12, 0.9 at 8 (the
// voxelizer's; an inscribed 12-gon, 4.5 % short in area, already left the floor too
// bright); at 1024² twice that. The medium tumbler is a 24-gon moved out to its
// circle's area (host/scene/mesh.hpp). llvmpipe sets up every triangle on the CPU, so
// the medium casters draw the map much faster than the 48-slice ones; the quality
// bench and test_scene's "shadow caster_mesh" (its bounds on area and covered texels)
// see the same shadows.
kiln::Lod casterLod(kiln::PassContext& ctx) {
    const std::string& mesh = ctx.getEnum("caster_mesh");
    if (mesh == "auto") return ctx.getInt("size") <= 1024 ? kiln::Lod::Medium : kiln::Lod::Fine;
    return mesh == "medium" ? kiln::Lod::Medium : mesh == "coarse" ? kiln::Lod::Low : kiln::Lod::Fine;
}

class Shadow final : public kiln::Pass {
public:
    kiln::PassDeclaration declare() const override {
        using namespace kiln;
        PassDeclaration d;
        d.output({.name = "depth", .kind = TextureKind::Depth2D, .format = Format::Depth32F,
                  .size = SizeRule::fromParam("size"), .doc = "depth from the lamp; see common/shadow.glsl",
                  .depthNear = 0.05f, .depthFar = 3.5f})  // shadow.glsl kLightNear, kLightFar
            .param(intChoiceParam("size", 2048, {256, 512, 1024, 2048, 4096}, "shadow map side in texels"))
            .param(floatParam("slope_bias", 2.0f, 0.0, 10.0, "polygon offset factor against shadow acne"))
            .param(enumParam("caster_mesh", "auto", {"auto", "fine", "medium", "coarse"},
                             "the casters' meshes: fine (the finest: tumblers at 48 slices, 32-segment spheres), "
                             "medium (24 slices, 16-segment spheres), coarse (the voxelizer's: 8, 10) or auto: "
                             "medium up to a 1024² map"));
        d.reads = kSceneShadowCasters | kSceneMeshes | kSceneLights;
        return d;
    }

    void execute(kiln::PassContext& ctx) override {
        GLuint program = ctx.program({.stages = {"shadow/shadow.vert", "shadow/shadow.frag"}});
        if (!program) return;
        const kiln::SceneView& scene = ctx.scene();
        const bool meshes = scene.count(kiln::kSceneMeshes) > 0;
        if (meshes && !drawStaticMeshes(ctx)) return;
        if (!ctx.framebuffer({}, "depth")) return;
        const kiln::TextureRef& depth = ctx.output("depth");
        if (meshes) {
            // The placed meshes do not move: drawn once into the pass's own map (again
            // when they, the light, the size or the program change), copied under the
            // moving casters each run.
            glCopyImageSubData(staticDepth_.id(), GL_TEXTURE_2D, 0, 0, 0, 0, depth.id, GL_TEXTURE_2D, 0, 0, 0, 0,
                               depth.width, depth.height, 1);
        } else {
            const float one = 1.0f;
            glClearBufferfv(GL_DEPTH, 0, &one);
        }
        // No caster: the cleared map (everything lit) is the answer.
        if (scene.count(kiln::kSceneShadowCasters) == 0) return;
        beginCasters(ctx, program);
        ctx.drawScene({.categories = kiln::kSceneShadowCasters, .lod = casterLod(ctx)});
    }

private:
    static void beginCasters(kiln::PassContext& ctx, GLuint program) {
        glEnable(GL_DEPTH_TEST);
        glDepthFunc(GL_LESS);
        glEnable(GL_POLYGON_OFFSET_FILL);
        glPolygonOffset(ctx.getFloat("slope_bias"), 4.0f);
        glUseProgram(program);
    }

    // The placed meshes' depth from the lamp in staticDepth_, their cut-outs cut, when
    // what it depends on changed. False when the pass failed.
    bool drawStaticMeshes(kiln::PassContext& ctx) {
        const kiln::SceneView& scene = ctx.scene();
        const GLuint program = ctx.program({.stages = {"shadow/cutout.vert", "shadow/cutout.frag"},
                                            .defines = {{"KILN_HAS_COLOR_LAYERS", scene.materialTextures[0] ? "1" : "0"}}});
        if (!program) return false;
        const int side = ctx.getInt("size");
        const StaticKey key{scene.version(kiln::kSceneMeshes), scene.version(kiln::kSceneLights), program, side,
                            ctx.getFloat("slope_bias"), scene.materialTextures[0]};
        if (key == built_ && staticDepth_) return true;
        if (!staticDepth_ || !framebuffer_ || staticDepth_.width() != side) {
            staticDepth_ = kiln::gl::Texture::create(GL_TEXTURE_2D, GL_DEPTH_COMPONENT32F, side, side, 1, 1,
                                                     "shadow.static_meshes");
            framebuffer_ = kiln::gl::createDepthFramebuffer(staticDepth_.id());
            if (!framebuffer_) {
                ctx.fail("the static meshes' depth map is incomplete as a framebuffer");
                return false;
            }
        }
        glBindFramebuffer(GL_FRAMEBUFFER, framebuffer_.id());
        glViewport(0, 0, side, side);
        const float one = 1.0f;
        glClearBufferfv(GL_DEPTH, 0, &one);
        beginCasters(ctx, program);
        kiln::gl::bindTexture(program, "u_colorLayers", scene.materialTextures[0]);
        ctx.drawScene({.categories = kiln::kSceneMeshes});
        built_ = key;
        return true;
    }

    struct StaticKey {
        uint64_t meshes = 0, light = 0;
        GLuint program = 0;
        int side = 0;
        float slopeBias = -1.0f;
        uint32_t textures = 0;
        bool operator==(const StaticKey&) const = default;
    };
    // A cache (a module reload starts over): what staticDepth_ was drawn from.
    StaticKey built_;
    kiln::gl::Texture staticDepth_;
    kiln::gl::FramebufferHandle framebuffer_;
};

}  // namespace

KILN_PASS_MODULE(shadow, Shadow)
