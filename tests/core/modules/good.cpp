#include <kiln/pass.hpp>
namespace {
class Good final : public kiln::Pass {
    kiln::PassDeclaration declare() const override {
        kiln::PassDeclaration d;
        d.output({.name = "color"}).param(kiln::floatParam("gain", 2.0f, 0.0, 10.0));
        return d;
    }
    void execute(kiln::PassContext&) override {}
};
}  // namespace
KILN_PASS_MODULE(test_good, Good)
