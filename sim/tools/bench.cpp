// kiln-sim bench: cost vs body count, error vs dt (with the observed order of
// convergence), and the seed's four-sphere tumbler contact vs the exact one.
#include "bench.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <array>
#include <functional>
#include <vector>

#include "kiln/sim/world.hpp"

using namespace kiln::sim;
namespace fs = std::filesystem;

namespace {

using Clock = std::chrono::steady_clock;

double seconds(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

// Frames per second of wall time: a short warm-up, then at least `minFrames` frames
// and at least `minSeconds`.
double framesPerSecond(World& w, int minFrames, double minSeconds) {
    for (int i = 0; i < 20; ++i) w.step();
    const auto t0 = Clock::now();
    int n = 0;
    while (n < minFrames || seconds(t0) < minSeconds) {
        w.step();
        ++n;
    }
    return n / seconds(t0);
}

// One marble in an empty box (bounces only off walls) and, separately, one ballasted
// tumbler rocking: smooth between events, unlike the chaotic full scene.
Scene marbleScene(double dt) {
    Scene s;
    s.physics.dt = dt;
    s.physics.substeps = 1;
    s.physics.friction = 0.0;
    s.marbles.push_back({{0.3, 0.5, 0.5}, {0.9, 0.0, 0.6}, 0.05, {1, 1, 1}});
    return s;
}

Scene tumblerScene(double dt) {
    Scene s;
    s.physics.dt = dt;
    s.physics.substeps = 1;
    s.physics.friction = 0.0;
    s.physics.tumblerMode = TumblerMode::Accurate;
    s.tumblers.push_back({{0.0, 0.0}, {0.1, 0.3}, {1, 0, 0}});
    return s;
}

std::string order(double coarse, double fine) {
    if (!(coarse > 0) || !(fine > 0)) return "";
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.2f", std::log2(coarse / fine));
    return buf;
}

}  // namespace

int runBenchmarks(const Scene& scene, const std::string& outDir, bool quick) {
    std::error_code ec;
    fs::create_directories(outDir, ec);
    if (ec) {
        std::fprintf(stderr, "kiln-sim: error: cannot create %s: %s\n", outDir.c_str(), ec.message().c_str());
        return 1;
    }
    auto open = [&](const char* name, std::ofstream& f) {
        f.open(fs::path(outDir) / name);
        if (!f) std::fprintf(stderr, "kiln-sim: error: cannot write %s/%s\n", outDir.c_str(), name);
        return bool(f);
    };
    const double minSeconds = quick ? 0.05 : 0.5;

    // ---- 1. cost vs body count ------------------------------------------------------
    {
        std::ofstream csv;
        if (!open("sim_steps.csv", csv)) return 1;
        csv << "case,balls,tumbler_contact,frames_per_second,substeps_per_second,particles\n";
        std::printf("cost per frame (%d sub-steps of %.3g ms; N balls = N marbles at random, uniform-grid broad phase)\n",
                    scene.physics.substeps, 1e3 * scene.physics.dt / scene.physics.substeps);
        std::printf("  %-22s %7s %14s %12s %10s\n", "case", "balls", "frames/s", "us/frame", "particles");
        struct Case {
            const char* name;
            int balls;  // −1: the scene's own
            TumblerContact contact;
        };
        const Case cases[] = {{"default scene", -1, scene.physics.tumblerContact},
                              {"default, four spheres", -1, TumblerContact::FourSpheres},
                              {"default, exact", -1, TumblerContact::Exact},
                              {"10 balls", 10, scene.physics.tumblerContact},
                              {"100 balls", 100, scene.physics.tumblerContact},
                              {"1000 balls", 1000, scene.physics.tumblerContact}};
        for (const Case& c : cases) {
            Scene s = scene;
            s.physics.tumblerContact = c.contact;
            World w(s);
            if (c.balls >= 0) {
                w.balls().clear();
                // Marbles only: a fireball would burn marbles away and change N mid-run.
                for (int i = 0; i < c.balls; ++i) w.spawnRandom(BallKind::Marble);
            }
            const int balls = int(w.balls().size());
            const double fps = framesPerSecond(w, c.balls >= 1000 ? 50 : 200, minSeconds);
            std::printf("  %-22s %7d %14.0f %12.1f %10zu\n", c.name, balls, fps, 1e6 / fps, w.particles().size());
            csv << '"' << c.name << "\"," << balls << "," << (c.contact == TumblerContact::Exact ? "exact" : "four_spheres")
                << "," << fps << "," << fps * s.physics.substeps << "," << w.particles().size() << "\n";
        }
    }

    // ---- 2. error vs dt ---------------------------------------------------------------
    {
        std::ofstream csv;
        if (!open("sim_convergence.csv", csv)) return 1;
        csv << "dt,marble_free_flight_error_m,marble_2s_rms_error_m,tumbler_2s_error_m,tumbler_us_per_sim_second\n";
        const double dts[] = {1.0 / 30, 1.0 / 60, 1.0 / 120, 1.0 / 240, 1.0 / 480};
        const int count = quick ? 3 : 5;
        // Each Δt against its own Δt/64 run. The marble: at t = 0.3 s (free flight, before
        // its first floor bounce: pure integrator error) and at t = 2 s (bounces: the
        // time-symmetric bounce turns back within one step, a first-order phase error
        // whose size depends on where the wall falls between steps: RMS over 16 starts).
        // The tumbler's upper-sphere centre at t = 2 s (rolling + rocking, 0.3 rad).
        auto marbleAt = [](double dt, double t, int variant = 0) {
            Scene s = marbleScene(dt);
            if (variant > 0) {  // other starts, so the bounce phases average out
                Rng rng{uint64_t(variant)};
                Vec3 p, v;
                for (int k = 0; k < 3; ++k) p[k] = rng.uniform(-0.5, 0.5);
                for (int k = 0; k < 3; ++k) v[k] = rng.uniform(-1.5, 1.5);
                s.marbles[0].position = p, s.marbles[0].velocity = v;
            }
            World w(s);
            const long n = std::lround(t / dt);
            for (long i = 0; i < n; ++i) w.step();
            return w.balls()[0].position;
        };
        auto tumblerAt = [](double dt, double t, double* usPerSimSecond) {
            World w(tumblerScene(dt));
            const long n = std::lround(t / dt);
            const auto t0 = Clock::now();
            for (long i = 0; i < n; ++i) w.step();
            if (usPerSimSecond) *usPerSimSecond = 1e6 * seconds(t0) / t;
            return w.tumblers()[0].upperCentre(w.shape());
        };
        std::printf("\nposition error vs dt (each against a dt/64 run; 1 sub-step)\n");
        std::printf("  %9s | %12s %6s | %12s %6s | %12s %6s %14s\n", "dt", "marble 0.3s", "order", "marble 2s rms", "order",
                    "tumbler 2s", "order", "us/sim-second");
        double prev[3] = {0, 0, 0};
        for (int k = 0; k < count; ++k) {
            const double dt = dts[k];
            const double e0 = glm::length(marbleAt(dt, 0.3) - marbleAt(dt / 64, 0.3));
            double e1 = 0;
            for (int v = 1; v <= 16; ++v) {
                const double e = glm::length(marbleAt(dt, 2.0, v) - marbleAt(dt / 64, 2.0, v));
                e1 += e * e / 16;
            }
            e1 = std::sqrt(e1);
            double cost = 0;
            const double e2 = glm::length(tumblerAt(dt, 2.0, &cost) - tumblerAt(dt / 64, 2.0, nullptr));
            std::printf("  1/%-7.0f | %12.3e %6s | %12.3e %6s | %12.3e %6s %14.1f\n", 1.0 / dt, e0,
                        order(prev[0], e0).c_str(), e1, order(prev[1], e1).c_str(), e2, order(prev[2], e2).c_str(), cost);
            csv << dt << "," << e0 << "," << e1 << "," << e2 << "," << cost << "\n";
            prev[0] = e0, prev[1] = e1, prev[2] = e2;
        }
    }

    // ---- 3. four-sphere vs exact tumbler contact ----------------------------------------
    {
        std::ofstream csv;
        if (!open("sim_contact.csv", csv)) return 1;
        csv << "pose_family,exact_distance,four_sphere_distance\n";
        RoundCone shape(scene.tumblerShape.b, scene.tumblerShape.t, scene.tumblerShape.alpha);
        const double b = shape.b(), t = shape.t();
        const Vec3 up(0, shape.upperCentre(), 0);
        std::printf("\nfour-sphere approximation vs exact round-cone separation (poses within 5 cm of contact)\n");
        std::printf("  %-26s %7s %13s %13s %9s %11s %11s\n", "poses", "n", "mean over m", "max over m", "missed",
                    "exact ns", "4-sph ns");
        struct Family {
            const char* name;
            double tiltLo, tiltHi;
        };
        const Family families[] = {{"upright-ish (tilt < 0.8)", 0.0, 0.8}, {"crossed, lying (70-110 deg)", 1.22, 1.92}};
        for (const Family& f : families) {
            Rng rng(7);
            std::vector<std::array<Vec3, 4>> poses;
            const int tries = quick ? 5000 : 40000;
            for (int i = 0; i < tries; ++i) {
                double tilt = rng.uniform(f.tiltLo, f.tiltHi);
                const Quat qa = glm::angleAxis(rng.uniform(0, 6.283185307179586), Vec3(0, 1, 0)) *
                                glm::angleAxis(tilt, Vec3(0, 0, 1));
                tilt = rng.uniform(f.tiltLo, f.tiltHi);
                const Quat qb = glm::angleAxis(rng.uniform(0, 6.283185307179586), Vec3(0, 1, 0)) *
                                glm::angleAxis(tilt, Vec3(0, 0, 1));
                Vec3 pb;
                pb.x = 2 * b + rng.uniform(-0.25, 0.2);
                pb.y = 0.0;
                pb.z = rng.uniform(-0.3, 0.3);
                poses.push_back({Vec3(0.0), qa * up, pb, pb + qb * up});
            }
            // Timing over all poses, then the error over the near-contact ones.
            volatile double sink = 0;
            auto t0 = Clock::now();
            for (auto& p : poses) sink = sink + roundConeSeparation(p[0], p[1], b, t, p[2], p[3], b, t).distance;
            const double exactNs = 1e9 * seconds(t0) / double(poses.size());
            t0 = Clock::now();
            for (auto& p : poses) sink = sink + fourSphereSeparation(p[0], p[1], b, t, p[2], p[3], b, t);
            const double approxNs = 1e9 * seconds(t0) / double(poses.size());
            double sum = 0, worst = 0;
            int n = 0, missed = 0, contacts = 0;
            for (auto& p : poses) {
                const double exact = roundConeSeparation(p[0], p[1], b, t, p[2], p[3], b, t).distance;
                if (std::abs(exact) > 0.05) continue;
                const double approx = fourSphereSeparation(p[0], p[1], b, t, p[2], p[3], b, t);
                csv << '"' << f.name << "\"," << exact << "," << approx << "\n";
                sum += approx - exact;
                worst = std::max(worst, approx - exact);
                contacts += exact < 0;
                missed += exact < 0 && approx >= 0;
                ++n;
            }
            char missedText[32];
            std::snprintf(missedText, sizeof missedText, "%d/%d", missed, contacts);
            std::printf("  %-26s %7d %13.3e %13.3e %9s %11.0f %11.0f\n", f.name, n, sum / std::max(n, 1), worst,
                        missedText, exactNs, approxNs);
        }
    }
    std::printf("\nwrote %s/sim_steps.csv, sim_convergence.csv, sim_contact.csv\n", outDir.c_str());
    return 0;
}
