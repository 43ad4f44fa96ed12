// kiln-sim — the simulation without OpenGL: run a scene and print its state hash and
// invariants, or run the physics benchmarks (tables + CSV).
#include <chrono>
#include <cmath>
#include <cstdio>
#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "kiln/sim/world.hpp"

using namespace kiln::sim;
namespace fs = std::filesystem;

namespace {

const char* kUsage = R"(kiln-sim — Kiln's physics without OpenGL

usage:
  kiln-sim run [--scene FILE] [--steps N] [--seed S]
      steps the world N frames; prints the state hash and invariants
  kiln-sim bench [--scene FILE] [--out DIR]
      steps/s vs ball count, convergence in dt, four-sphere vs exact tumbler contact;
      prints tables and writes CSV to DIR (default bench-out/)
)";

int fail(const std::string& m) {
    std::fprintf(stderr, "kiln-sim: error: %s\n", m.c_str());
    return 1;
}

double stepsPerSecond(World& w, int steps) {
    const auto t0 = std::chrono::steady_clock::now();
    for (int i = 0; i < steps; ++i) w.step();
    return steps / std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// One marble bouncing in an empty box and one tumbler rocking: smooth enough between
// bounces for a convergence study, unlike the full scene whose collisions are chaotic.
Scene convergenceScene(double dt) {
    Scene s;
    s.physics.dt = dt;
    s.physics.substeps = 1;
    s.physics.friction = 0.0;
    // Far apart, so the marble's wall and floor bounces are the only events.
    s.tumblers.push_back({{-0.5, -0.6}, {0.0, 0.3}, {1, 0, 0}});
    s.marbles.push_back({{0.3, 0.5, 0.5}, {0.5, 0.0, 0.3}, 0.05, {1, 1, 1}});
    return s;
}

}  // namespace

int main(int argc, char** argv) {
    if (argc < 2 || std::string(argv[1]) == "--help" || std::string(argv[1]) == "-h") {
        std::printf("%s", kUsage);
        return argc < 2 ? 1 : 0;
    }
    const std::string command = argv[1];
    std::string scenePath = std::string(KILN_SOURCE_DIR) + "/scenes/cornell.json", outDir = "bench-out";
    long long steps = 1000, seed = -1;
    for (int i = 2; i < argc; ++i) {
        std::string a = argv[i];
        if (i + 1 >= argc) return fail(a + " needs a value (or is unknown); see kiln-sim --help");
        std::string v = argv[++i];
        char* end = nullptr;
        if (a == "--scene") scenePath = v;
        else if (a == "--out") outDir = v;
        else if (a == "--steps" || a == "--seed") {
            long long n = std::strtoll(v.c_str(), &end, 10);
            if (*end || n < 0) return fail(a + " " + v + ": expected a non-negative integer");
            (a == "--steps" ? steps : seed) = n;
        } else {
            return fail("unknown argument \"" + a + "\"; see kiln-sim --help");
        }
    }
    Scene scene;
    std::string error;
    if (!loadScene(scenePath, scene, error)) return fail(error);
    if (seed >= 0) scene.physics.seed = uint64_t(seed);

    if (command == "run") {
        World world(scene);
        for (long long i = 0; i < steps; ++i) world.step();
        std::printf("steps %lld  t %.4f s  hash %016llx\n", steps, world.time(), (unsigned long long)world.stateHash());
        std::printf("tumblers %zu  balls %zu  particles %zu\n", world.tumblers().size(), world.balls().size(),
                    world.particles().size());
        std::printf("finite %s  max |q|-1 %.3g  max containment violation %.3g m\n", world.allFinite() ? "yes" : "NO",
                    world.maxQuaternionError(), world.maxContainmentViolation());
        return world.allFinite() ? 0 : 1;
    }
    if (command != "bench") return fail("unknown command \"" + command + "\"; see kiln-sim --help");

    fs::create_directories(outDir);
    // 1. Cost vs ball count.
    {
        std::ofstream csv(fs::path(outDir) / "sim_steps.csv");
        csv << "balls,steps_per_second\n";
        std::printf("steps per second (frame = %d sub-steps of %.5f s)\n  %8s %14s\n", scene.physics.substeps,
                    scene.physics.dt / scene.physics.substeps, "balls", "steps/s");
        for (int extra : {-1, 10, 100, 1000}) {
            World w(scene);
            if (extra >= 0) {
                w.balls().clear();
                for (int i = 0; i < extra; ++i) w.spawnRandom(i % 10 == 0 ? BallKind::Fireball : BallKind::Marble);
            }
            const int n = extra >= 1000 ? 200 : 2000;
            const double sps = stepsPerSecond(w, n);
            const int balls = int(w.balls().size());
            std::printf("  %8s %14.0f\n", extra < 0 ? ("default(" + std::to_string(balls) + ")").c_str() : std::to_string(extra).c_str(), sps);
            csv << (extra < 0 ? balls : extra) << "," << sps << "\n";
        }
    }
    // 2. Position error at t = 2 s against a dt/64 run.
    {
        std::ofstream csv(fs::path(outDir) / "sim_convergence.csv");
        csv << "dt,marble_error_m,tumbler_error_m\n";
        const double dts[] = {1.0 / 60, 1.0 / 120, 1.0 / 240, 1.0 / 480};
        const double fine = dts[3] / 64.0;
        // The marble is compared at t = 0.3 s, before its first floor bounce: a bounce
        // shifts its phase by up to one step, which swamps the integrator's error at a
        // fixed later time. The rocking tumbler is compared at t = 2 s.
        auto run = [](double dt) {
            World w(convergenceScene(dt));
            Vec3 marble(0.0);
            const int n = int(std::lround(2.0 / dt)), marbleStep = int(std::lround(0.3 / dt));
            for (int i = 0; i < n; ++i) {
                w.step();
                if (i + 1 == marbleStep) marble = w.balls()[0].position;
            }
            return std::make_pair(marble, w.tumblers()[0].upperCentre(w.shape()));
        };
        auto ref = run(fine);
        std::printf("\nposition error (marble at t = 0.3 s, tumbler top at t = 2 s) vs a dt = %.2e run\n  %10s %14s %8s %14s %8s\n", fine, "dt", "marble m",
                    "order", "tumbler m", "order");
        double prevM = 0, prevT = 0;
        for (double dt : dts) {
            auto r = run(dt);
            const double em = glm::length(r.first - ref.first), et = glm::length(r.second - ref.second);
            std::printf("  %10.5f %14.3e %8s %14.3e %8s\n", dt, em,
                        prevM > 0 ? std::to_string(std::log2(prevM / em)).substr(0, 5).c_str() : "",
                        et, prevT > 0 ? std::to_string(std::log2(prevT / et)).substr(0, 5).c_str() : "");
            csv << dt << "," << em << "," << et << "\n";
            prevM = em, prevT = et;
        }
    }
    // 3. Four-sphere approximation vs exact round-cone separation.
    {
        std::ofstream csv(fs::path(outDir) / "sim_contact.csv");
        csv << "exact_distance,four_sphere_distance\n";
        RoundCone shape(scene.tumblerShape.b, scene.tumblerShape.t, scene.tumblerShape.alpha);
        Rng rng(7);
        double sumErr = 0, maxErr = 0;
        int n = 0, missed = 0;
        for (int i = 0; i < 20000; ++i) {
            // Random tilted poses side by side, 0..0.15 m apart at the base.
            const Quat qa = glm::angleAxis(rng.uniform(-0.8, 0.8), Vec3(0, 0, 1)) * glm::angleAxis(rng.uniform(-0.8, 0.8), Vec3(1, 0, 0));
            const Quat qb = glm::angleAxis(rng.uniform(-0.8, 0.8), Vec3(0, 0, 1)) * glm::angleAxis(rng.uniform(-0.8, 0.8), Vec3(1, 0, 0));
            const Vec3 pa(0, 0, 0), pb(2 * shape.b() + rng.uniform(-0.1, 0.15), 0, rng.uniform(-0.1, 0.1));
            const Vec3 ua = pa + qa * Vec3(0, shape.upperCentre(), 0), ub = pb + qb * Vec3(0, shape.upperCentre(), 0);
            const double exact = roundConeSeparation(pa, ua, shape.b(), shape.t(), pb, ub, shape.b(), shape.t()).distance;
            auto sdfB = [&](const Vec3& p) { return shape.sdf(glm::inverse(qb) * (p - pb)); };
            auto sdfA = [&](const Vec3& p) { return shape.sdf(glm::inverse(qa) * (p - pa)); };
            const double approx = std::min({sdfB(pa) - shape.b(), sdfB(ua) - shape.t(), sdfA(pb) - shape.b(), sdfA(ub) - shape.t()});
            if (std::abs(exact) > 0.05) continue;  // only poses near contact matter
            csv << exact << "," << approx << "\n";
            const double err = approx - exact;
            sumErr += std::abs(err);
            maxErr = std::max(maxErr, std::abs(err));
            if (exact < 0 && approx >= 0) ++missed;
            ++n;
        }
        std::printf("\nfour-sphere vs exact tumbler separation (%d poses within 5 cm of contact)\n"
                    "  mean |error| %.3e m, max %.3e m, contacts missed %d (%.1f %%)\n",
                    n, sumErr / n, maxErr, missed, 100.0 * missed / std::max(n, 1));
    }
    std::printf("\nwrote %s/sim_steps.csv, sim_convergence.csv, sim_contact.csv\n", outDir.c_str());
    return 0;
}
