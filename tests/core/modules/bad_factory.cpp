// A module whose factory throws (e.g. a resource it needs is missing).
#include <kiln/pass.hpp>
#include <stdexcept>
namespace {
kiln::Pass* create() { throw std::runtime_error("out of widgets"); }
void destroy(kiln::Pass* p) { delete p; }
const KilnPassModule kModule{kiln::kPassAbiVersion, "bad_factory", &create, &destroy};
}  // namespace
extern "C" __attribute__((visibility("default"))) const KilnPassModule* kiln_pass_module() { return &kModule; }
