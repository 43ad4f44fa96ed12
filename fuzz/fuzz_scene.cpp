// Fuzz target: the scene loader. Any input must give a scene or one bounded, named
// error; an accepted scene must step some frames and stay finite and inside the box.
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "kiln/sim/scene.hpp"
#include "kiln/sim/world.hpp"

namespace {
void require(bool ok, const char* what, const std::string& detail = {}) {
    if (ok) return;
    std::fprintf(stderr, "fuzz_scene: invariant broken: %s\n%.2000s\n", what, detail.c_str());
    std::abort();
}
bool finite(const glm::dvec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    using namespace kiln::sim;
    const std::string text(reinterpret_cast<const char*>(data), size);
    const SceneResult r = parseSceneText(text);
    if (!r) {
        const std::string line = r.error.toString("scenes/fuzz.json");
        require(line.size() <= 600, "an error message longer than 600 bytes", line);
        require(line.find('\n') == std::string::npos, "an error message of several lines", line);
        return 0;
    }
    World w(r.scene);
    for (int frame = 0; frame < 8; ++frame) {
        w.step();
        for (const Ball& b : w.balls()) {
            require(finite(b.position) && finite(b.velocity), "a ball is not finite");
            for (int a = 0; a < 3; ++a)
                require(std::abs(b.position[a]) <= 1.0 - b.radius + 1e-9, "a ball left the box",
                        "frame " + std::to_string(frame) + " axis " + std::to_string(a) + " at " +
                            std::to_string(b.position[a]) + " radius " + std::to_string(b.radius));
        }
        for (const Tumbler& t : w.tumblers()) {
            require(finite(t.position) && finite(t.velocity), "a tumbler is not finite");
            for (int a = 0; a < 3; ++a) require(std::abs(t.position[a]) <= 1.0 + 1e-9, "a tumbler left the box");
        }
        for (const Particle& p : w.particles()) require(finite(p.position), "a particle is not finite");
        require(w.particles().size() <= World::kMaxParticles, "more particles than the pool holds");
    }
    return 0;
}
