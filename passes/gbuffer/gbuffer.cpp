// gbuffer — draws every mesh of the scene into albedo, world-space normal, emitted
// radiance and depth, the marbles and fireballs as spheres traced over their screen
// rectangles, the particles as point sprites over them, into the emission only. The
// first pass of every pipeline.
#include <kiln/pass.hpp>

namespace {

class GBuffer final : public kiln::Pass {
public:
    kiln::PassDeclaration declare() const override {
        using namespace kiln;
        PassDeclaration d;
        d.output({.name = "albedo", .format = Format::RGBA8, .doc = "linear albedo"})
            .output({.name = "normal", .format = Format::RGBA16F, .doc = "world-space unit normal; w = 1 on geometry"})
            .output({.name = "emissive", .format = Format::RGBA16F,
                     .doc = "emitted radiance; a = 1 on geometry, 2 where a particle hides the surface the other "
                            "outputs hold (it writes only this), 0 elsewhere"})
            .output({.name = "depth", .kind = TextureKind::Depth2D, .format = Format::Depth32F,
                     .depthNear = kCameraNear, .depthFar = kCameraFar})
            .internal({.name = "wood", .format = Format::RGBA8, .size = SizeRule::fixed(1024, 1024),
                       .mips = kFullMipChain,
                       .doc = "the floor's grain baked over x, z in [-1,1] (2 mm texels), re-baked when its colours change"})
            .param(boolParam("particles", true, "draw the particles"))
            .param(enumParam("particle_mode", "points", {"points", "mesh"},
                             "points: one point sprite per particle, the disc its sphere covers; mesh: its octahedron"))
            .param(enumParam("sphere_mode", "traced", {"traced", "mesh"},
                             "the marbles and fireballs: traced = each pixel's ray against the sphere over its "
                             "projected rectangle (exact silhouette, normal and depth; two triangles a sphere); "
                             "mesh = their UV-sphere meshes by size on screen"));
        d.reads = kSceneStatic | kSceneMeshes | kSceneBodies | kSceneParticles | kSceneCamera;
        return d;
    }

    void execute(kiln::PassContext& ctx) override {
        // One program per material (gbuffer.vert): the floor's grain is a lookup that the
        // rest of the picture must not pay for.
        GLuint program = ctx.program({.stages = {"gbuffer/gbuffer.vert", "gbuffer/gbuffer.frag"}, .defines = {{"KILN_WOOD", "0"}}});
        GLuint woodProgram = ctx.program({.stages = {"gbuffer/gbuffer.vert", "gbuffer/gbuffer.frag"}, .defines = {{"KILN_WOOD", "1"}}});
        const bool particles = ctx.getBool("particles");
        const bool points = particles && ctx.getEnum("particle_mode") == "points";
        GLuint pointProgram = points ? ctx.program({.stages = {"gbuffer/particle.vert", "gbuffer/particle.frag"}}) : 0;
        GLuint particleMeshProgram =
            particles && !points ? ctx.program({.stages = {"gbuffer/gbuffer.vert", "gbuffer/gbuffer.frag"},
                                                .defines = {{"KILN_WOOD", "0"}, {"KILN_PARTICLE", "1"}}})
                                 : 0;
        const bool tracedSpheres = ctx.getEnum("sphere_mode") == "traced";
        GLuint sphereProgram =
            tracedSpheres ? ctx.program({.stages = {"gbuffer/sphere.vert", "gbuffer/sphere.frag"}}) : 0;
        GLuint bake = ctx.program({.stages = {"gbuffer/wood.comp"}});
        GLuint background = ctx.program({.stages = {"gbuffer/background.vert", "gbuffer/background.frag"}});
        // The placed meshes' materials, each texture array's lookups only where it exists.
        const kiln::SceneView& scene = ctx.scene();
        const bool meshes = scene.count(kiln::kSceneMeshes) > 0;
        GLuint texturedProgram =
            meshes ? ctx.program({.stages = {"gbuffer/textured.vert", "gbuffer/textured.frag"},
                                  .defines = {{"KILN_HAS_COLOR_LAYERS", scene.materialTextures[0] ? "1" : "0"},
                                              {"KILN_HAS_DATA_LAYERS", scene.materialTextures[1] ? "1" : "0"}}})
                   : 0;
        if (!program || !woodProgram || !bake || !background || (points && !pointProgram) || (meshes && !texturedProgram) ||
            (particles && !points && !particleMeshProgram) ||
            (tracedSpheres && !sphereProgram))
            return;
        // The floor's grain, baked: sampled through its mips it is the grain averaged
        // over each pixel, as the reference sees it (closer to it than the grain evaluated
        // at pixel centres), for a little more G-buffer time. Re-baked when the wood
        // colours or the texture change.
        const kiln::TextureRef& wood = ctx.internal("wood");
        const auto& f = ctx.scene().frame;
        if (wood.id != bakedTexture_ || f.ringsLight != bakedLight_ || f.ringsDark != bakedDark_ || bake != bakedWith_) {
            glUseProgram(bake);
            kiln::gl::bindImage(bake, "u_wood", wood.id, 0, false, GL_WRITE_ONLY, GL_RGBA8);
            glDispatchCompute(GLuint((wood.width + 7) / 8), GLuint((wood.height + 7) / 8), 1);
            glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT);
            glGenerateTextureMipmap(wood.id);
            bakedTexture_ = wood.id, bakedLight_ = f.ringsLight, bakedDark_ = f.ringsDark, bakedWith_ = bake;
        }
        if (!ctx.framebuffer({"albedo", "normal", "emissive"}, "depth")) return;
        // Where only bodies moved, only what they change (kiln/pass.hpp): the clears
        // and the draws are scissored to it, the rest keeps last frame's surfaces.
        const kiln::TextureRef& target = ctx.output("albedo");
        kiln::forEachRedrawRect(ctx, target.width, target.height, 0, [&] {
            // Depth only: the colours are written where geometry is and by the background
            // after it (below), which the depth test keeps to the rest. The three colour
            // clears are dear on llvmpipe.
            const float one = 1.0f;
            glClearBufferfv(GL_DEPTH, 0, &one);
            glEnable(GL_DEPTH_TEST);
            glDepthFunc(GL_LESS);
            glUseProgram(program);
            // The bodies are closed, so their back faces never show: culled, they cost
            // llvmpipe no setup, and no back face wins a depth tie at a silhouette (a few
            // pixels did). The walls and the lamp's dome are open surfaces, seen from either
            // side. The bodies first: they stand in front of the walls, whose hidden
            // fragments the depth test then rejects before shading.
            glEnable(GL_CULL_FACE);
            glCullFace(GL_BACK);
            ctx.drawScene({.categories = tracedSpheres ? kiln::kSceneRoundCones : kiln::kSceneBodies});
            glDisable(GL_CULL_FACE);
            if (tracedSpheres) drawTracedSpheres(ctx, sphereProgram);
            if (meshes) {
                // One-sided materials with their back faces culled (glTF's default: no
                // setup for half the triangles); double-sided ones show either side, the
                // back face's normal turned to the viewer, as the walls' are.
                glUseProgram(texturedProgram);
                kiln::gl::bindTexture(texturedProgram, "u_colorLayers", scene.materialTextures[0]);
                kiln::gl::bindTexture(texturedProgram, "u_dataLayers", scene.materialTextures[1]);
                glEnable(GL_CULL_FACE);
                ctx.drawScene({.categories = kiln::kSceneMeshes, .sides = kiln::Sides::OneSided});
                glDisable(GL_CULL_FACE);
                ctx.drawScene({.categories = kiln::kSceneMeshes, .sides = kiln::Sides::TwoSided});
            }
            glUseProgram(program);
            ctx.drawScene({.categories = kiln::kSceneStatic});
            // The floor, the one wood-grained instance (a wall of the box).
            glUseProgram(woodProgram);
            kiln::gl::bindTexture(woodProgram, "u_wood", wood.id);
            ctx.drawScene({.categories = kiln::kScenePlanes});

            glUseProgram(background);
            glDepthMask(GL_FALSE);
            ctx.drawFullscreenTriangle();
            if (particles) drawParticles(ctx, points ? pointProgram : particleMeshProgram, points);
            glDepthMask(GL_TRUE);
        });
    }

private:
    // The particles, last, over the surfaces and the background: depth tested, but
    // only their emission written, its alpha 2 (the `emissive` output's doc). Albedo,
    // normal and depth stay those of the surface behind, so a particle moving over it
    // changes none of what composite keeps of its lamp light: composite's kept tiles
    // need not follow the particles (many fireballs' sparks would move most of them),
    // and cone_trace gathers for the surface, not for a spark a few pixels wide. One
    // particle over another: the one drawn later shows.
    void drawParticles(kiln::PassContext& ctx, GLuint program, bool points) {
        const uint32_t count = ctx.scene().count(kiln::kSceneParticles);
        if (count == 0) return;
        glColorMaski(0, GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
        glColorMaski(1, GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
        glDepthMask(GL_FALSE);
        glUseProgram(program);
        if (points) {
            // Thousands of particles a few pixels wide: one point each, not 8 triangles
            // (thousands of octahedra are dear for llvmpipe, which sets up each on the CPU).
            glUniform1ui(glGetUniformLocation(program, "u_first"), ctx.scene().firstInstance(kiln::kSceneParticles));
            glEnable(GL_PROGRAM_POINT_SIZE);
            glBindVertexArray(emptyVertexArray());
            glDrawArrays(GL_POINTS, 0, GLsizei(count));
            glBindVertexArray(0);
            glDisable(GL_PROGRAM_POINT_SIZE);
        } else {
            glEnable(GL_CULL_FACE);
            glCullFace(GL_BACK);
            ctx.drawScene({.categories = kiln::kSceneParticles});
            glDisable(GL_CULL_FACE);
        }
        glColorMaski(0, GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
        glColorMaski(1, GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    }

    // sphere_mode traced: the marbles and the fireballs (neighbours in the instance
    // buffer, which holds the categories in bit order), each its screen rectangle.
    void drawTracedSpheres(kiln::PassContext& ctx, GLuint sphereProgram) {
        const uint32_t count = ctx.scene().count(kiln::kSceneSpheres | kiln::kSceneGlowingSpheres);
        if (count == 0) return;
        glUseProgram(sphereProgram);
        glUniform1ui(glGetUniformLocation(sphereProgram, "u_first"), ctx.scene().firstInstance(kiln::kSceneSpheres));
        glBindVertexArray(emptyVertexArray());
        glDrawArrays(GL_TRIANGLES, 0, GLsizei(6 * count));
        glBindVertexArray(0);
    }

    // Attribute-less: the particles' and spheres' vertex shaders read the instance buffer.
    GLuint emptyVertexArray() {
        if (!emptyVao_) emptyVao_ = kiln::gl::createVertexArray();
        return emptyVao_.id();
    }

    kiln::gl::VertexArrayHandle emptyVao_;
    // What the wood texture was last baked from (a cache: a reload starts over).
    GLuint bakedTexture_ = 0, bakedWith_ = 0;
    glm::vec4 bakedLight_{-1.0f}, bakedDark_{-1.0f};
};

}  // namespace

KILN_PASS_MODULE(gbuffer, GBuffer)
