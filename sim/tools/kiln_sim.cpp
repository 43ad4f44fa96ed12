// kiln-sim — the simulation without OpenGL: run a scene and print its state hash and
// invariants, or run the physics benchmarks (tables, CSV, PNG plots). Every failure exits
// non-zero with one line "kiln-sim: error: ..." on stderr.
#include <chrono>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "bench.hpp"
#include "kiln/data_root.hpp"
#include "kiln/sim/world.hpp"

using namespace kiln::sim;

namespace {

const char* kUsage = R"(kiln-sim - Kiln's physics without OpenGL

usage:
  kiln-sim run   [--scene FILE] [--steps N] [--seed S] [--mode course|accurate]
                 [--contact four_spheres|exact]
      loads the scene, steps the world N frames (default 1000) and prints the state
      hash and the invariants (finite state, |q| - 1, containment); exits 1 if an
      invariant is broken
  kiln-sim bench [--scene FILE] [--out DIR] [--quick]
      cost per frame for the scene and 10/100/1000 balls; the tumbler's rocking
      period (vs the quadrature reference) and 3D energy/Jellett drift vs dt and
      sub-steps with time per simulated second and the observed order; marbles vs
      the closed-form free fall; four-sphere vs exact tumbler contact (poses and a
      crowded scene); prints tables, writes CSV and PNG plots to DIR (default
      bench-out/)
  kiln-sim --help

The default scene is scenes/cornell.json of the source tree.
)";

int fail(const std::string& m) {
    std::fprintf(stderr, "kiln-sim: error: %s\n", m.c_str());
    return 1;
}

bool parseCount(const std::string& v, long long& out) {
    if (v.empty()) return false;
    char* end = nullptr;
    errno = 0;
    const long long n = std::strtoll(v.c_str(), &end, 10);
    if (*end || errno || n < 0) return false;
    out = n;
    return true;
}

}  // namespace

// `kiln-sim run`: steps the world and checks the invariants every frame.
int runScene(const Scene& scene, const std::string& scenePath, long long steps) {
    World world(scene);
    double worstQ = 0, worstOut = 0;
    bool finite = true;
    const auto t0 = std::chrono::steady_clock::now();
    for (long long i = 0; i < steps && finite; ++i) {
        world.step();
        worstQ = std::max(worstQ, world.maxQuaternionError());
        worstOut = std::max(worstOut, world.maxContainmentViolation());
        finite = world.allFinite();
    }
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    int asleep = 0;
    for (auto& t : world.tumblers()) asleep += t.asleep;
    std::printf("scene %s  seed %llu  mode %s  contact %s\n", scenePath.c_str(), (unsigned long long)scene.physics.seed,
                scene.physics.tumblerMode == TumblerMode::Course ? "course" : "accurate",
                scene.physics.tumblerContact == TumblerContact::Exact ? "exact" : "four_spheres");
    std::printf("steps %lld  t %.4f s  hash %016llx  (%.0f steps/s)\n", steps, world.time(),
                (unsigned long long)world.stateHash(), seconds > 0 ? double(steps) / seconds : 0.0);
    std::printf("tumblers %zu (%d asleep)  balls %zu  particles %zu\n", world.tumblers().size(), asleep,
                world.balls().size(), world.particles().size());
    std::printf("invariants over the run: finite %s  max | |q| - 1 | %.3g  max containment violation %.3g m\n",
                finite ? "yes" : "NO", worstQ, worstOut);
    // Bounds: quaternions are renormalised every sub-step (1e-6 is generous), containment
    // is exact per sphere up to rounding (1e-9 m).
    if (!finite) return fail("the state became NaN/Inf");
    if (worstQ > 1e-6) return fail("a quaternion norm drifted beyond 1e-6");
    if (worstOut > 1e-9) return fail("a body left the box by more than 1e-9 m");
    return 0;
}

int main(int argc, char** argv) {
    std::vector<std::string> args(argv + 1, argv + argc);
    for (auto& a : args)
        if (a == "--help" || a == "-h") {
            std::printf("%s", kUsage);
            return 0;
        }
    if (args.empty()) return fail("no command (run or bench); see kiln-sim --help");
    const std::string command = args[0];
    if (command != "run" && command != "bench") return fail("unknown command \"" + command + "\"; see kiln-sim --help");

    std::string scenePath = (kiln::shippedFiles().data / "scenes/cornell.json").string(), outDir = "bench-out", mode, contact;
    long long steps = 1000, seed = -1;
    bool quick = false;
    for (size_t i = 1; i < args.size(); ++i) {
        const std::string& a = args[i];
        if (a == "--quick" && command == "bench") {
            quick = true;
            continue;
        }
        const bool known = a == "--scene" || (command == "bench" && a == "--out") ||
                           (command == "run" && (a == "--steps" || a == "--seed" || a == "--mode" || a == "--contact"));
        if (!known) return fail("unknown option \"" + a + "\" for " + command + "; see kiln-sim --help");
        if (i + 1 >= args.size()) return fail(a + " needs a value");
        const std::string& v = args[++i];
        if (a == "--scene") scenePath = v;
        else if (a == "--out") outDir = v;
        else if (a == "--mode") mode = v;
        else if (a == "--contact") contact = v;
        else if (!parseCount(v, a == "--steps" ? steps : seed))
            return fail(a + " " + v + ": expected a non-negative integer");
    }

    SceneResult loaded = loadSceneFile(scenePath);
    if (!loaded) return fail(loaded.error.toString(scenePath));
    Scene scene = loaded.scene;
    if (seed >= 0) scene.physics.seed = uint64_t(seed);
    if (!mode.empty()) {
        if (mode != "course" && mode != "accurate") return fail("--mode " + mode + ": expected course or accurate");
        scene.physics.tumblerMode = mode == "course" ? TumblerMode::Course : TumblerMode::Accurate;
    }
    if (!contact.empty()) {
        if (contact != "exact" && contact != "four_spheres")
            return fail("--contact " + contact + ": expected four_spheres or exact");
        scene.physics.tumblerContact = contact == "exact" ? TumblerContact::Exact : TumblerContact::FourSpheres;
    }

    if (command == "bench") return runBenchmarks(scene, outDir, quick);
    return runScene(scene, scenePath, steps);
}
