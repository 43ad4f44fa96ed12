// voxel_view — a ray-marched view of the voxel radiance at a chosen mip level, for
// looking at what the cone tracer sees (pipelines/voxels.json).
#include <kiln/pass.hpp>

namespace {

class VoxelView final : public kiln::Pass {
public:
    kiln::PassDeclaration declare() const override {
        using namespace kiln;
        PassDeclaration d;
        d.input({.name = "voxels_iso", .kind = TextureKind::Color3D, .required = false})
            .input({.name = "voxels_aniso", .kind = TextureKind::Color3D, .required = false})
            .output({.name = "color", .format = Format::RGBA8})
            .param(floatParam("mip", 0.0f, 0.0, 6.0, "level in base-voxel units"))
            .param(floatParam("exposure", 1.0f, 0.01, 16.0))
            .shader("voxel_view/voxel_view.frag");
        d.reads = kSceneCamera;
        return d;
    }

    void execute(kiln::PassContext& ctx) override {
        GLuint program = ctx.program({.stages = {"common/fullscreen.vert", "voxel_view/voxel_view.frag"}});
        if (!program || !ctx.framebuffer({"color"})) return;
        glUseProgram(program);
        glBindTextureUnit(4, ctx.input("voxels_iso").id);
        glBindTextureUnit(5, ctx.input("voxels_aniso").id);
        glUniform1f(glGetUniformLocation(program, "u_lod"), ctx.getFloat("mip"));
        glUniform1f(glGetUniformLocation(program, "u_exposure"), ctx.getFloat("exposure"));
        ctx.drawFullscreenTriangle();
    }
};

}  // namespace

KILN_PASS_MODULE(voxel_view, VoxelView)
