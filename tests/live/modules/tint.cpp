// A tiny module built twice (TINT_VERSION 1 and 2) for the module-reload test: it
// fills its output with a colour that depends on the version and on its parameter. Its
// optional input is there to be bound after a pass under test (the fault tests): it
// runs whenever that pass's output changes.
#include <kiln/pass.hpp>
namespace {
class Tint final : public kiln::Pass {
    kiln::PassDeclaration declare() const override {
        kiln::PassDeclaration d;
        d.input({.name = "under", .kind = kiln::TextureKind::Color2D, .required = false})
            .output({.name = "color", .format = kiln::Format::RGBA8})
            .param(kiln::floatParam("level", 0.5f, 0.0, 1.0, "the green channel"));
        return d;
    }
    void execute(kiln::PassContext& ctx) override {
        if (!ctx.framebuffer({"color"})) return;
        const float c[4] = {TINT_VERSION == 1 ? 1.0f : 0.0f, ctx.getFloat("level"), TINT_VERSION == 2 ? 1.0f : 0.0f, 1.0f};
        glClearBufferfv(GL_COLOR, 0, c);
    }
};
}  // namespace
KILN_PASS_MODULE(live_tint, Tint)
