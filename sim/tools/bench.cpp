// kiln-sim bench: cost vs body count; the tumbler's rocking period and 3D invariants vs
// Δt and sub-steps against independent references (the period by quadrature, energy and
// Jellett's quantity that the exact flow conserves), with time per simulated second;
// marbles against the closed-form free fall; the course design's four-sphere tumbler contact vs
// the exact one. Tables on stdout, CSV + PNG plots in the output folder.
#include "bench.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <vector>

#include "kiln/sim/world.hpp"
#include <kiln/plot_script.hpp>
#include "reference.hpp"

using namespace kiln::sim;
namespace fs = std::filesystem;

namespace {

using Clock = std::chrono::steady_clock;
constexpr double kDeg = M_PI / 180.0;

double seconds(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

// Frames per second of wall time: a short warm-up, then at least `minFrames` frames and
// at least `minSeconds`.
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

std::string order(double coarse, double fine) {
    if (!(coarse > 0) || !(fine > 0)) return "";
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.2f", std::log2(coarse / fine));
    return buf;
}

struct Out {
    std::string dir;
    bool open(const char* name, std::ofstream& f) const {
        f.open(fs::path(dir) / name);
        if (!f) std::fprintf(stderr, "kiln-sim: error: cannot write %s/%s\n", dir.c_str(), name);
        return bool(f);
    }
};

// ---- 1. cost vs body count --------------------------------------------------------------

bool benchCost(const Scene& scene, const Out& out, double minSeconds) {
    std::ofstream csv;
    if (!out.open("sim_steps.csv", csv)) return false;
    csv << "case,balls,tumbler_contact,frames_per_second,us_per_frame,substeps_per_second,particles\n";
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
            << "," << fps << "," << 1e6 / fps << "," << fps * s.physics.substeps << "," << w.particles().size() << "\n";
    }
    return true;
}

// ---- 2. the tumbler against its references ----------------------------------------------

Scene rockingScene(const Scene& base, double dt, int sub, double tilt) {
    Scene s;
    s.physics = base.physics;
    s.tumblerShape = base.tumblerShape;
    s.physics.dt = dt;
    s.physics.substeps = sub;
    s.physics.maxSubsteps = sub;  // the Δt asked for: no adaptive sub-steps in this sweep
    s.physics.friction = 0.0;
    s.physics.tumblerMode = TumblerMode::Accurate;
    s.tumblers.push_back({{0.0, 0.0}, {0.0, tilt}, {1, 0, 0}});
    return s;
}

struct RockingRow {
    double dt = 0;
    int sub = 1;
    double err10 = 0, err60 = 0, energy = 0, jellett = 0, usPerSimSecond = 0;
};

// 3D: tilted 30°, spun at 12 rad/s about the vertical, 20 s; the largest energy and
// Jellett deviations (relative to the kinetic energy and to |J₀|) and the step time.
void invariantDrift(const Scene& base, RockingRow& row, double duration) {
    World w(rockingScene(base, row.dt, row.sub, 30 * kDeg));
    Tumbler& t = w.tumblers()[0];
    t.angularVelocity = Vec3(0.3, 12.0, 0.2);
    t.velocity = w.shape().b() * Vec3(-t.angularVelocity.z, 0.0, t.angularVelocity.x);
    const double e0 = w.tumblerEnergy(0), j0 = w.tumblerJellett(0);
    const double ke = 0.5 * glm::dot(t.angularVelocity, w.rollingInertia(0) * t.angularVelocity);
    double stepping = 0.0;
    while (w.time() < duration) {
        const auto t0 = Clock::now();
        w.step();
        stepping += seconds(t0);
        row.energy = std::max(row.energy, std::abs(w.tumblerEnergy(0) - e0) / ke);
        row.jellett = std::max(row.jellett, std::abs(w.tumblerJellett(0) - j0) / std::abs(j0));
    }
    row.usPerSimSecond = 1e6 * stepping / w.time();
}

std::vector<RockingRow> benchRocking(const Scene& base, const Out& out, bool quick) {
    std::vector<RockingRow> rows;
    std::ofstream csv;
    if (!out.open("sim_rocking.csv", csv)) return rows;
    csv << "dt,substeps,substep_dt,period_error_10deg,period_error_60deg,energy_drift,jellett_drift,us_per_sim_second\n";
    const World probe(rockingScene(base, base.physics.dt, 1, 0.1));
    const double m = probe.tumblerMass(), R = probe.shape().b(), h = base.physics.ballastH;
    const double IG = probe.massProperties().inertiaCom.z, g = base.physics.gravity;
    const double exact10 = reference::rockingPeriod(m, R, h, IG, g, 10 * kDeg);
    const double exact60 = reference::rockingPeriod(m, R, h, IG, g, 60 * kDeg);
    std::printf("\ntumbler (accurate mode, exact rolling, RK4) against independent references, no friction\n");
    std::printf("  period error: relative to the quadrature T(10deg) = %.6f s, T(60deg) = %.6f s (4 periods);\n", exact10,
                exact60);
    std::printf("  drift: max |E - E0| / KE and |J - J0| / |J0| over %s s of 3D tilt + spin\n", quick ? "5" : "20");
    std::printf("  (the 60deg error changes sign as dt shrinks, so its ratios say little; the order is 10deg's)\n");
    std::printf("  %8s %4s | %11s %6s %11s | %10s %10s | %12s\n", "dt", "sub", "T err 10deg", "order", "T err 60deg",
                "E drift", "J drift", "us/sim-s");
    const double inv[] = {15, 30, 60, 120, 240, 480};
    for (int sub : {1, 4}) {
        double prev = 0;
        for (int k = 0; k < (quick ? 3 : 6); ++k) {
            RockingRow row;
            row.dt = 1.0 / inv[k], row.sub = sub;
            World w10(rockingScene(base, row.dt, sub, 10 * kDeg)), w60(rockingScene(base, row.dt, sub, 60 * kDeg));
            row.err10 = std::abs(reference::measuredPeriod(w10, 4.2 * exact10) - exact10) / exact10;
            row.err60 = std::abs(reference::measuredPeriod(w60, 4.2 * exact60) - exact60) / exact60;
            invariantDrift(base, row, quick ? 5.0 : 20.0);
            std::printf("  1/%-6.0f %4d | %11.3e %6s %11.3e | %10.3e %10.3e | %12.1f\n", inv[k], sub, row.err10,
                        order(prev, row.err10).c_str(), row.err60, row.energy, row.jellett, row.usPerSimSecond);
            csv << row.dt << "," << sub << "," << row.dt / sub << "," << row.err10 << "," << row.err60 << "," << row.energy
                << "," << row.jellett << "," << row.usPerSimSecond << "\n";
            prev = row.err10;
            rows.push_back(row);
        }
    }
    return rows;
}

// ---- 3. marbles against the closed form -------------------------------------------------

bool benchMarble(const Out& out, bool quick) {
    // Free flight from (0.7, 0.9, 0) at v_y = 0.5 (beside the lamp, no bounce for 0.3 s):
    // against y(t) = y₀ + v₀t − ½gt², semi-implicit Euler is first order (error ½gΔt·t).
    // Then 10 s of wall and floor bounces: the modified energy E′ should stay exact.
    std::ofstream csv;
    if (!out.open("sim_marble.csv", csv)) return false;
    csv << "dt,free_flight_error_m,energy_drift_relative\n";
    std::printf("\nmarble against the closed-form free fall (0.3 s) and its modified energy E' (10 s of bounces)\n");
    std::printf("  %8s | %12s %6s | %12s\n", "dt", "y error (m)", "order", "E' drift");
    double prev = 0;
    for (double inv : {30.0, 60.0, 120.0, 240.0, 480.0}) {
        if (quick && inv > 120) break;
        Scene s;
        s.physics.dt = 1.0 / inv, s.physics.substeps = 1, s.physics.maxSubsteps = 1;
        s.marbles.push_back({{0.7, 0.9, 0.0}, {0.0, 0.5, 0.0}, 0.05, {1, 1, 1}});
        World w(s);
        const long n = std::lround(0.3 * inv);
        for (long i = 0; i < n; ++i) w.step();
        const double t = n / inv, exact = 0.9 + 0.5 * t - 0.5 * s.physics.gravity * t * t;
        const double err = std::abs(w.balls()[0].position.y - exact);
        s.marbles[0] = {{0.1, 0.3, -0.2}, {1.3, 0.7, 0.9}, 0.05, {1, 1, 1}};
        World b(s);
        const double e0 = b.ballEnergy(0);
        double drift = 0;
        while (b.time() < 10.0) {
            b.step();
            drift = std::max(drift, std::abs(b.ballEnergy(0) - e0) / std::abs(e0));
        }
        std::printf("  1/%-6.0f | %12.3e %6s | %12.3e\n", inv, err, order(prev, err).c_str(), drift);
        csv << 1.0 / inv << "," << err << "," << drift << "\n";
        prev = err;
    }
    return true;
}

// ---- 4. four-sphere vs exact tumbler contact --------------------------------------------

bool benchContactPoses(const Scene& scene, const Out& out, bool quick) {
    std::ofstream csv;
    if (!out.open("sim_contact.csv", csv)) return false;
    csv << "pose_family,exact_distance,four_sphere_distance\n";
    RoundCone shape(scene.tumblerShape.b, scene.tumblerShape.t, scene.tumblerShape.alpha);
    const double b = shape.b(), t = shape.t();
    const Vec3 up(0, shape.upperCentre(), 0);
    std::printf("\nfour-sphere approximation vs exact round-cone separation (poses within 5 cm of contact)\n");
    std::printf("  %-26s %7s %13s %13s %9s %11s %11s\n", "poses", "n", "mean over m", "max over m", "missed", "exact ns",
                "4-sph ns");
    const std::pair<const char*, std::array<double, 2>> families[] = {{"upright-ish (tilt < 0.8)", {0.0, 0.8}},
                                                                      {"crossed, lying (70-110 deg)", {1.22, 1.92}}};
    for (const auto& [name, tilts] : families) {
        Rng rng(7);
        std::vector<std::array<Vec3, 4>> poses;
        for (int i = 0, tries = quick ? 5000 : 40000; i < tries; ++i) {
            const double ta = rng.uniform(tilts[0], tilts[1]), ya = rng.uniform(0, 2 * M_PI);
            const double tb = rng.uniform(tilts[0], tilts[1]), yb = rng.uniform(0, 2 * M_PI);
            const Quat qa = glm::angleAxis(ya, Vec3(0, 1, 0)) * glm::angleAxis(ta, Vec3(0, 0, 1));
            const Quat qb = glm::angleAxis(yb, Vec3(0, 1, 0)) * glm::angleAxis(tb, Vec3(0, 0, 1));
            Vec3 pb(0.0);
            pb.x = 2 * b + rng.uniform(-0.25, 0.2);
            pb.z = rng.uniform(-0.3, 0.3);
            poses.push_back({Vec3(0.0), qa * up, pb, pb + qb * up});
        }
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
            csv << '"' << name << "\"," << exact << "," << approx << "\n";
            sum += approx - exact, worst = std::max(worst, approx - exact);
            contacts += exact < 0, missed += exact < 0 && approx >= 0, ++n;
        }
        char missedText[32];
        std::snprintf(missedText, sizeof missedText, "%d/%d", missed, contacts);
        std::printf("  %-26s %7d %13.3e %13.3e %9s %11.0f %11.0f\n", name, n, sum / std::max(n, 1), worst, missedText,
                    exactNs, approxNs);
    }
    return true;
}

bool benchContactScene(const Scene& scene, const Out& out, bool quick) {
    // The scene with 25 more marbles and 4 fireballs, each tumbler contact method: cost,
    // the deepest tumbler overlap seen after a frame (by the exact separation) and the
    // total energy's drift (balls + tumblers + burnt marbles, relative to the initial
    // kinetic energy; only meaningful when the scene's contacts are elastic).
    std::ofstream csv;
    if (!out.open("sim_contact_scene.csv", csv)) return false;
    csv << "tumbler_contact,us_per_frame,deepest_overlap_m,energy_drift_relative\n";
    std::printf("\ntumbler contact methods in a crowded scene (+25 marbles, +4 fireballs, %s s)\n", quick ? "5" : "20");
    std::printf("  %-14s %12s %16s %14s\n", "method", "us/frame", "deepest overlap", "energy drift");
    for (TumblerContact method : {TumblerContact::FourSpheres, TumblerContact::Exact}) {
        Scene s = scene;
        s.physics.tumblerContact = method;
        World w(s);
        for (int i = 0; i < 25; ++i) w.spawnRandom(BallKind::Marble);
        for (int i = 0; i < 4; ++i) w.spawnRandom(BallKind::Fireball);
        double ke = 0.0;
        for (const Ball& b : w.balls()) ke += 0.5 * b.mass() * glm::dot(b.velocity, b.velocity);
        const double e0 = w.totalEnergy();
        double stepping = 0.0, overlap = 0.0, drift = 0.0;
        long frames = 0;
        while (w.time() < (quick ? 5.0 : 20.0)) {
            const auto t0 = Clock::now();
            w.step();
            stepping += seconds(t0), ++frames;
            overlap = std::min(overlap, w.deepestTumblerOverlap());
            drift = std::max(drift, std::abs(w.totalEnergy() + w.removedBallEnergy() - e0) / ke);
        }
        const char* name = method == TumblerContact::Exact ? "exact" : "four_spheres";
        std::printf("  %-14s %12.1f %16.3e %14.3e\n", name, 1e6 * stepping / frames, overlap, drift);
        csv << name << "," << 1e6 * stepping / frames << "," << overlap << "," << drift << "\n";
    }
    return true;
}

// ---- 5. figures -------------------------------------------------------------------------

// matplotlib draws them from sim_rocking.csv (scripts/plot.py).
bool writePlots(const Out& out) {
    std::string error;
    const std::string about = kiln::plotAbout("the simulation alone, one thread of " + kiln::cpuModel());
    if (!kiln::drawPlot({"sim", (fs::path(out.dir) / "sim_rocking.csv").string(), out.dir, "--about", about}, error)) {
        std::fprintf(stderr, "kiln-sim: error: %s\n", error.c_str());
        return false;
    }
    return true;
}

}  // namespace

int runBenchmarks(const Scene& scene, const std::string& outDir, bool quick) {
    std::error_code ec;
    fs::create_directories(outDir, ec);
    if (ec) {
        std::fprintf(stderr, "kiln-sim: error: cannot create %s: %s\n", outDir.c_str(), ec.message().c_str());
        return 1;
    }
    const Out out{outDir};
    Scene rocking = scene;
    if (rocking.physics.ballastH <= 0.0) rocking.physics.ballastH = 0.05;  // the reference needs h > 0
    if (!benchCost(scene, out, quick ? 0.05 : 0.5)) return 1;
    const std::vector<RockingRow> rows = benchRocking(rocking, out, quick);
    if (rows.empty() || !benchMarble(out, quick) || !benchContactPoses(scene, out, quick) ||
        !benchContactScene(scene, out, quick) || !writePlots(out))
        return 1;
    std::printf("\nwrote %s/: sim_steps.csv, sim_rocking.csv, sim_marble.csv, sim_contact.csv, sim_contact_scene.csv,\n"
                "  sim_time_vs_error.png, sim_error_vs_dt.png\n",
                outDir.c_str());
    return 0;
}
