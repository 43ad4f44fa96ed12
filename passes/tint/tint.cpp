#include <kiln/pass.hpp>
class Tint final : public kiln::Pass {
  kiln::PassDeclaration declare() const override {
    kiln::PassDeclaration d;
    d.input({.name = "color", .kind = kiln::TextureKind::Color2D})
     .output({.name = "color", .format = kiln::Format::RGBA16F})
     .param(kiln::colorParam("tint", {1, 0.5f, 0.5f}, "multiplies the colour"));
    return d;
  }
  void execute(kiln::PassContext& ctx) override {
    GLuint prog = ctx.program({.stages = {"common/fullscreen.vert", "tint/tint.frag"}});
    if (!prog || !ctx.framebuffer({"color"})) return;  // the host shows the error
    glUseProgram(prog);
    kiln::gl::bindTexture(prog, "u_color", ctx.input("color").id);  // the shader's unit
    auto t = ctx.getColor("tint");
    glUniform3f(glGetUniformLocation(prog, "u_tint"), t[0], t[1], t[2]);
    ctx.drawFullscreenTriangle();
  }
};
KILN_PASS_MODULE(tint, Tint)
