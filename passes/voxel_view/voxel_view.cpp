// voxel_view — the course design's voxel figure: ray-marches the voxel radiance at a
// chosen mip level from the camera, front to back, drawing each voxel as a box (nearest
// lookups, one step per voxel boundary crossed: an exact 3D DDA). Bind `voxels` to
// voxel_mip.iso (any level) or voxelize.radiance (level 0 only).
#include <kiln/pass.hpp>

namespace {

class VoxelView final : public kiln::Pass {
public:
    kiln::PassDeclaration declare() const override {
        using namespace kiln;
        PassDeclaration d;
        d.input({.name = "voxels", .kind = TextureKind::Color3D, .doc = "voxel_mip.iso or voxelize.radiance"})
            .output({.name = "color", .format = Format::RGBA8, .doc = "tonemapped, gamma-encoded view"})
            .param(intParam("mip", 0, 0, 7, "mip level to show (clamped to the volume's levels)"))
            .param(floatParam("exposure", 1.0f, 0.01, 16.0))
            .param(floatParam("min_opacity", 0.01f, 0.0, 1.0, "voxels less opaque than this are skipped"));
        d.reads = kSceneCamera;
        return d;
    }

    void execute(kiln::PassContext& ctx) override {
        GLuint prog = ctx.program({.stages = {"common/fullscreen.vert", "voxel_view/voxel_view.frag"}});
        if (!prog || !ctx.framebuffer({"color"})) return;
        const kiln::TextureRef& v = ctx.input("voxels");
        glUseProgram(prog);
        kiln::gl::bindTexture(prog, "u_voxels", v.id);
        glUniform1i(glGetUniformLocation(prog, "u_mip"), std::min(ctx.getInt("mip"), v.levels - 1));
        glUniform1f(glGetUniformLocation(prog, "u_exposure"), ctx.getFloat("exposure"));
        glUniform1f(glGetUniformLocation(prog, "u_minOpacity"), ctx.getFloat("min_opacity"));
        ctx.drawFullscreenTriangle();
    }
};

}  // namespace

KILN_PASS_MODULE(voxel_view, VoxelView)
