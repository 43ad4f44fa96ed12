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
#include "command_line/command_line.hpp"
#include "kiln/data_root.hpp"
#include "kiln/sim/world.hpp"

using namespace kiln::sim;

namespace {

int fail(const std::string& m) {
    std::fprintf(stderr, "kiln-sim: error: %s\n", m.c_str());
    return 1;
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
    CLI::App app{"kiln-sim — Kiln's physics without OpenGL", "kiln-sim"};
    kiln::cli::configure(app);
    app.require_subcommand(1);
    std::string scenePath = (kiln::shippedFiles().data / "scenes/cornell.json").string(), outDir = "bench-out", mode, contact;
    long long steps = 1000, seed = -1;
    bool quick = false;
    CLI::App* run = app.add_subcommand("run", "step the world N frames and print the state hash and the invariants (finite "
                                              "state, |q| - 1, containment); exits 1 if one is broken");
    run->add_option("--scene", scenePath, "the scene (default scenes/cornell.json)")->type_name("FILE");
    run->add_option("--steps", steps, "frames to step (default 1000)")->type_name("N")->check(CLI::NonNegativeNumber.description(""));
    run->add_option("--seed", seed, "the simulation's seed (default the scene's)")->type_name("N")->check(CLI::NonNegativeNumber.description(""));
    run->add_option("--mode", mode, "the tumblers' dynamics")->check(CLI::IsMember({"course", "accurate"}));
    run->add_option("--contact", contact, "the tumblers' contact model")->check(CLI::IsMember({"four_spheres", "exact"}));
    CLI::App* bench = app.add_subcommand("bench", "cost per frame, the rocking period against quadrature, energy drift "
                                                  "against dt, free fall, contact models; tables, CSV and plots in OUT");
    bench->add_option("--scene", scenePath, "the scene (default scenes/cornell.json)")->type_name("FILE");
    bench->add_option("--out", outDir, "where the CSV and plots go (default bench-out)")->type_name("DIR");
    bench->add_flag("--quick", quick, "fewer, shorter runs");
    if (const std::optional<int> exitNow = kiln::cli::parse(app, argc, argv)) return *exitNow;
    const std::string command = run->parsed() ? "run" : "bench";

    SceneResult loaded = loadSceneFile(scenePath);
    if (!loaded) return fail(loaded.error.toString(scenePath));
    Scene scene = loaded.scene;
    if (seed >= 0) scene.physics.seed = uint64_t(seed);
    if (!mode.empty()) {
        scene.physics.tumblerMode = mode == "course" ? TumblerMode::Course : TumblerMode::Accurate;
    }
    if (!contact.empty()) {
        scene.physics.tumblerContact = contact == "exact" ? TumblerContact::Exact : TumblerContact::FourSpheres;
    }

    if (command == "bench") return runBenchmarks(scene, outDir, quick);
    return runScene(scene, scenePath, steps);
}
