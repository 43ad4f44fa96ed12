// A pass from outside Kiln's tree: darkens the image towards its corners,
// out = in × (1 − kStrength · 2r²), r the distance from the centre in units of the
// image's longer side, so the centre keeps its value and a square's corners get
// 1 − kStrength.
#include <kiln/pass.hpp>

constexpr float kStrength = 0.5f;

class Vignette final : public kiln::Pass {
  kiln::PassDeclaration declare() const override {
    kiln::PassDeclaration d;
    d.input({.name = "color", .kind = kiln::TextureKind::Color2D})
     .output({.name = "color", .format = kiln::Format::RGBA8, .doc = "the input, darker towards the corners"});
    return d;
  }
  void execute(kiln::PassContext& ctx) override {
    GLuint prog = ctx.program({.stages = {"common/fullscreen.vert", "vignette/vignette.frag"}});
    if (!prog || !ctx.framebuffer({"color"})) return;  // the host shows the error
    glUseProgram(prog);
    kiln::gl::bindTexture(prog, "u_color", ctx.input("color").id);
    glUniform1f(glGetUniformLocation(prog, "u_strength"), kStrength);
    ctx.drawFullscreenTriangle();
  }
};
KILN_PASS_MODULE(vignette, Vignette)
