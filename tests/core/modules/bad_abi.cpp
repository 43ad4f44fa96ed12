// A module built against a future pass ABI: the host must refuse it before calling
// anything in it, naming both versions.
#include <kiln/pass.hpp>
namespace {
const KilnPassModule kModule{999, "bad_abi", nullptr, nullptr};
}
extern "C" __attribute__((visibility("default"))) const KilnPassModule* kiln_pass_module() { return &kModule; }
