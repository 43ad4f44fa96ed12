// What collisions keep, and containment at every Δt: restitution honoured exactly, the
// lamp bounce energy-neutral, the shipped scene keeping its energy for 10 simulated
// minutes, and no body leaving the box / entering a tumbler from Δt = 1/1000 to 1/15 s.
#include <catch2/catch.hpp>

#include <cmath>
#include <cstdio>
#include <tuple>
#include <string>

#include "kiln/sim/world.hpp"
#include "support.hpp"

using namespace kiln::sim;
using namespace kiln::sim::test;

namespace {

// Smallest SDF of any ball centre against any tumbler (negative: a centre inside).
double ballCentreClearance(const World& w) {
    double worst = 1e9;
    for (int i = 0; i < int(w.tumblers().size()); ++i)
        for (const Ball& b : w.balls()) worst = std::min(worst, w.tumblerSdf(i, b.position));
    return worst;
}

// Mechanical energy from the state alone, with the independently derived mass properties
// that test_shape.cpp checks the shape's quadrature against (12 digits), rather than the
// simulation's own sum (World::totalEnergy): balls ½m|v|² + m·g·y (fireballs float: no
// g); a tumbler (accurate mode, rolling on its lower sphere) ½m|ω×(G−P)|² +
// ½ωᵀ(R·I_G·Rᵀ)ω + m·g·G_y with G = O − h·axis, P = O − b·ŷ.
double independentEnergy(const World& w) {
    const Scene& s = w.scene();
    const double g = s.physics.gravity, m = s.tumblerShape.mass, h = s.physics.ballastH, b = s.tumblerShape.b;
    const glm::dmat3 inertiaG(0.0242731416696 * m, 0, 0, 0, 0.0146421435034 * m, 0, 0, 0, 0.0242731416696 * m);
    double e = 0.0;
    for (const Ball& ball : w.balls())
        e += 0.5 * ball.mass() * glm::dot(ball.velocity, ball.velocity) +
             (ball.kind == BallKind::Fireball ? 0.0 : ball.mass() * g * ball.position.y);
    for (const Tumbler& t : w.tumblers()) {
        const glm::dmat3 R = glm::mat3_cast(t.orientation);
        const Vec3 G = t.position - h * (R * Vec3(0, 1, 0)), P = t.position - Vec3(0, b, 0);
        const Vec3 vG = glm::cross(t.angularVelocity, G - P);
        e += 0.5 * m * glm::dot(vG, vG) + 0.5 * glm::dot(t.angularVelocity, R * inertiaG * glm::transpose(R) * t.angularVelocity) +
             m * g * G.y;
    }
    return e;
}

}  // namespace

TEST_CASE("tumbler against tumbler honours its restitution with both rolling responses", "[sim][conservation]") {
    // Two upright tumblers whose lower spheres just touch (1e-9 m overlap, so the push
    // is negligible), rolling into each other with some spin. After the impulse the
    // relative normal velocity at the contact is −e times what it was (1e-9: the push
    // of 1e-9 m shifts the lever arms by as much), the rolling kinetic energy ½ωᵀAω is
    // kept for e = 1 (1e-12) and lost otherwise.
    for (double e : {1.0, 0.5, 0.0}) {
        Scene s;
        s.physics.friction = 0.0;
        s.physics.restitution.tumblerTumbler = e;
        s.tumblers.push_back({{-0.2 + 0.5e-9, 0.0}, {0.0, 0.0}, {1, 0, 0}});
        s.tumblers.push_back({{0.2 - 0.5e-9, 0.0}, {0.0, 0.0}, {0, 1, 0}});
        World w(s);
        w.tumblers()[0].angularVelocity = Vec3(0.2, 1.0, -4.0);
        w.tumblers()[1].angularVelocity = Vec3(-0.3, 0.0, 2.0);
        for (auto& t : w.tumblers()) t.velocity = 0.2 * Vec3(-t.angularVelocity.z, 0.0, t.angularVelocity.x);
        const Vec3 h(0.0, -0.8, 0.0), n(1.0, 0.0, 0.0);  // the touching point, A → B
        auto vn = [&] { return glm::dot(w.pointVelocity(1, h) - w.pointVelocity(0, h), n); };
        auto kinetic = [&] {
            double k = 0;
            for (int i = 0; i < 2; ++i)
                k += 0.5 * glm::dot(w.tumblers()[size_t(i)].angularVelocity,
                                    w.rollingInertia(i) * w.tumblers()[size_t(i)].angularVelocity);
            return k;
        };
        const double before = vn(), k0 = kinetic();
        REQUIRE(before < -1.0);
        REQUIRE(w.resolveTumblerPair(0, 1) < 0.0);
        INFO("e = " << e << ": vn " << before << " -> " << vn());
        CHECK(vn() == Approx(-e * before).margin(1e-9));
        if (e == 1.0) CHECK(std::abs(kinetic() - k0) / k0 < 1e-12);
        else CHECK(kinetic() < k0);
    }
}

TEST_CASE("the lamp bounce keeps a marble's modified energy exactly", "[sim][conservation]") {
    // A marble thrown up at the dome bounces off it and the floor for 1e5 sub-steps. The
    // dome bounce reflects the mid-step velocity u = v − ½gΔt·ŷ about the dome normal,
    // which keeps E′ = ½|u|² + g·y + const exactly; only rounding remains (1e-10, as for
    // the walls in test_world.cpp).
    Scene s;
    s.physics.friction = 0.0;
    s.marbles.push_back({{0.12, 0.0, 0.05}, {0.2, 4.2, 0.1}, 0.05, {1, 1, 1}});
    World w(s);
    const double e0 = w.ballEnergy(0);
    double worst = 0.0;
    int lampHits = 0;
    const Vec3 c = s.lamp.center;
    for (int i = 0; i < 100000 / s.physics.substeps / kScale; ++i) {
        w.step();
        worst = std::max(worst, std::abs(w.ballEnergy(0) - e0) / std::abs(e0));
        lampHits += glm::length(w.balls()[0].position - c) < s.lamp.radius + 0.05 + 0.02 && w.balls()[0].velocity.y < 0 &&
                    w.balls()[0].position.y > 0.6;
    }
    INFO("worst relative E' error " << worst << ", frames near the dome moving down " << lampHits);
    CHECK(lampHits > 5 / kScale);
    CHECK(worst < 1e-10);
}

TEST_CASE("the energy-keeping box keeps its energy for 10 simulated minutes", "[sim][conservation]") {
    // tests/sim/data/energy_keeping.json: every contact elastic, no rolling friction. Balls
    // and tumblers trade energy at every hit (a tumbler is as heavy as a marble), so the
    // balls' share swings; what must hold is the total, balls (modified energy E′) +
    // tumblers (½ωᵀAω + m·g·G_y) + what burnt marbles took with them. Bound: 1e-4 of
    // the balls' initial kinetic energy; measured 4.5e-6 (22 µJ). Every bounce is
    // energy-exact by construction; what remains is the RK4 tumbler drift, rounding and
    // the rare corrections that cannot be paid for (a ball too slow to pay for being
    // lifted out of a tumbler).
    // Every frame: nothing outside the box, no ball centre inside a tumbler.
    Scene s = energyKeepingScene();
    REQUIRE(s.physics.friction == 0.0);
    World w(s);
    double kinetic0 = 0.0;
    for (const Ball& b : w.balls()) kinetic0 += 0.5 * b.mass() * glm::dot(b.velocity, b.velocity);
    const double e0 = w.totalEnergy();
    double worst = 0.0, worstOut = 0.0, clearance = 1e9, ballsMin = 1e9, ballsMax = -1e9;
    const long frames = std::lround(600.0 / s.physics.dt) / kScale;
    for (long f = 0; f < frames; ++f) {
        w.step();
        worst = std::max(worst, std::abs(w.totalEnergy() + w.removedBallEnergy() - e0));
        worstOut = std::max(worstOut, w.maxContainmentViolation());
        clearance = std::min(clearance, ballCentreClearance(w));
        if (f > frames / 2) {
            double balls = 0.0;
            for (const Ball& b : w.balls()) balls += 0.5 * b.mass() * glm::dot(b.velocity, b.velocity);
            ballsMin = std::min(ballsMin, balls), ballsMax = std::max(ballsMax, balls);
        }
    }
    INFO("energy drift " << worst << " J of " << kinetic0 << " J kinetic; balls' kinetic energy in the second half "
                         << ballsMin << ".." << ballsMax << " J; ball-centre clearance " << clearance);
    CHECK(worst < 1e-4 * kinetic0);
    CHECK(worstOut < 1e-9);
    CHECK(clearance > 0.0);
    CHECK(ballsMax > 0.1 * kinetic0);  // the balls are still moving, not crawling
    REQUIRE(w.allFinite());
}

TEST_CASE("containment at every dt from 1/1000 to 1/15 s and any sub-step count", "[sim][conservation][stress]") {
    // A crowded box (the shipped scene plus 25 marbles and 4 fireballs), checked after
    // every frame. Bounds: containment exact per sphere (1e-9 m: rounding of the push),
    // no ball centre inside a tumbler, tumbler-tumbler overlap under 1 mm (the passes of
    // pair + wall corrections stop at 0.1 mm; measured ≤ 1e-5 m).
    for (double inv : {1000.0, 240.0, 60.0, 30.0, 15.0}) {
        for (int sub : {1, 3}) {
            Scene s = shippedScene();
            s.physics.dt = 1.0 / inv;
            s.physics.substeps = sub;
            World w(s);
            for (int i = 0; i < 25; ++i) w.spawnRandom(BallKind::Marble);
            for (int i = 0; i < 4; ++i) w.spawnRandom(BallKind::Fireball);
            double out = 0.0, overlap = 0.0, clearance = 1e9;
            const int frames = int(std::lround(20.0 * inv)) / kScale;  // 20 simulated seconds
            for (int f = 0; f < frames; ++f) {
                w.step();
                out = std::max(out, w.maxContainmentViolation());
                overlap = std::min(overlap, w.deepestTumblerOverlap());
                clearance = std::min(clearance, ballCentreClearance(w));
            }
            INFO("dt 1/" << inv << " x" << sub << ": out " << out << " m, tumbler overlap " << overlap
                         << " m, ball-centre clearance " << clearance << " m");
            REQUIRE(w.allFinite());
            CHECK(out < 1e-9);
            CHECK(overlap > -1e-3);
            CHECK(clearance > 0.0);
        }
    }
}

TEST_CASE("a toppled tumbler does not crawl, at any dt", "[sim][conservation]") {
    // A uniform tumbler (centre of mass above O) falls onto its side and rests there.
    // Rolling back onto the lying pose moves O by the matching rolling distance, so no
    // slip accumulates: once down it stays put (1e-6 m over 5 s), at Δt 1/240 and 1/30.
    for (double inv : {240.0, 30.0}) {
        Scene s;
        s.physics.friction = 0.0;
        s.physics.dt = 1.0 / inv;
        s.physics.substeps = 1;
        s.physics.ballastH = -0.0521160345185;
        s.tumblers.push_back({{0.0, 0.0}, {0.0, 5.0 * M_PI / 180.0}, {1, 0, 0}});
        World w(s);
        while (w.time() < 4.0) w.step();
        const Vec3 p0 = w.tumblers()[0].position;
        double moved = 0.0;
        while (w.time() < 9.0) {
            w.step();
            moved = std::max(moved, glm::length(w.tumblers()[0].position - p0));
        }
        const double tilt = std::acos(std::clamp(w.tumblers()[0].axis().y, -1.0, 1.0));
        INFO("dt 1/" << inv << ": moved " << moved << " m, tilt " << tilt * 180 / M_PI << " deg");
        CHECK(moved < 1e-6);
        CHECK(std::abs(tilt - std::acos((0.1 - 0.2) / w.shape().upperCentre())) < 1e-6);
    }
}

TEST_CASE("large steps: every sub-step option stays finite, contained and energy-bounded, or is refused by name",
          "[sim][conservation][stress]") {
    // A crowded all-elastic, frictionless box (the shipped tumblers and 25 marbles, no
    // fireballs: nothing burns), 30 simulated seconds at Δt 1/30 to 0.1 s, with adaptive
    // sub-steps from 1 and 4, and with fixed ones at the longest the scene file allows.
    // Energy comes from independentEnergy (above), not the simulation's own sum. Before
    // sub-steps were bounded, Δt 0.1 with one fixed sub-step reached NaN in 68 frames (a
    // tumbler spun to 10^34 rad/s), Δt 1/15 gained 150 %, adaptive from one sub-step
    // 6 % at Δt 0.1; before the box clamp paid for lifting a ball, Δt 1/30 with 4 fixed
    // sub-steps gained 7 %.
    // Bounds: energy within 3 % of the start — every contact keeps the modified energy
    // E′ = ½|u|² + g·y exactly, and the plain energy measured here differs from E′ by
    // m·g·Δt_sub·v_y/2 a ball, about 1 % of this box's energy at 1/240 s (measured
    // 0.984–1.013 over the sweep) —, no ball centre inside a tumbler, nothing outside.
    for (double dt : {1.0 / 30.0, 0.05, 1.0 / 15.0, 0.1}) {
        struct Option {
            const char* name;
            int substeps, maxSubsteps;
        };
        const int fixedCount = int(std::ceil(dt / kMaxFixedSubstep - 1e-9));
        for (const Option& o : {Option{"adaptive from 1", 1, 256}, Option{"adaptive from 4", 4, 256},
                                Option{"fixed at the bound", fixedCount, fixedCount}}) {
            Scene s = energyKeepingScene();
            s.fireballs.clear();
            s.physics.dt = dt;
            s.physics.substeps = o.substeps;
            s.physics.maxSubsteps = o.maxSubsteps;
            s.physics.wallDecay = 1.0;
            s.physics.restitution = {};  // every kind 1 by default: elastic
            s.physics.restitution.tumblerTumbler = 1.0;
            s.physics.restitution.tumblerFloor = 1.0;
            s.physics.friction = 0.0;
            World w(s);
            for (int i = 0; i < 25; ++i) w.spawnRandom(BallKind::Marble);
            const double e0 = independentEnergy(w);
            double lo = e0, hi = e0, out = 0.0, clearance = 1e9;
            const int frames = int(std::lround(30.0 / dt)) / kScale;
            for (int f = 0; f < frames && w.allFinite(); ++f) {
                w.step();
                const double e = independentEnergy(w);
                lo = std::min(lo, e), hi = std::max(hi, e);
                out = std::max(out, w.maxContainmentViolation());
                clearance = std::min(clearance, ballCentreClearance(w));
            }
            INFO("dt " << dt << ", " << o.name << " (" << o.substeps << ".." << o.maxSubsteps << "): energy " << lo / e0
                       << ".." << hi / e0 << " of the start, out " << out << " m, clearance " << clearance << " m");
            REQUIRE(w.allFinite());
            CHECK(hi < 1.03 * e0);
            CHECK(lo > 0.97 * e0);
            CHECK(out < 1e-9);
            CHECK(clearance > 0.0);
        }
        // One sub-step fewer than the bound needs is refused, naming the fix: fixed, and
        // an adaptive ceiling too low to reach it.
        char dtText[32];
        std::snprintf(dtText, sizeof dtText, "%.17g", dt);
        for (auto [substeps, ceiling, fix] : {std::tuple{fixedCount - 1, 1, "set substeps to at least "},
                                              std::tuple{1, fixedCount - 1, "set max_substeps to at least "}}) {
            Scene refused = shippedScene();
            SceneError error;
            const std::string text = std::string("{\"tumblers\": [], \"physics\": {\"dt\": ") + dtText +
                                     ", \"substeps\": " + std::to_string(substeps) + ", \"max_substeps\": " +
                                     std::to_string(ceiling) + "}}";
            INFO(text);
            CHECK_FALSE(parseScene(text, refused, error));
            CHECK(error.path == "physics.max_substeps");
            CHECK_THAT(error.message, Catch::Contains(fix + std::to_string(fixedCount)));
        }
    }
}
