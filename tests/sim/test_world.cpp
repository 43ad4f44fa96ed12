// The world: impulses, energy, rocking, stress, determinism, picking.
#include <catch2/catch.hpp>

#include <cmath>

#include "kiln/sim/world.hpp"
#include "support.hpp"

using namespace kiln::sim;
using namespace kiln::sim::test;

namespace {

Scene emptyScene() {
    Scene s;
    s.physics.friction = 0.0;
    return s;
}

// stateHash() of scenes/cornell.json, seed 1, after 1500 frames (see the determinism test).
constexpr uint64_t kCornellHash1500 = 0xc9221bb00095fdbdull;

double tiltAboutZ(const Tumbler& t) {
    const Vec3 a = t.axis();
    return std::atan2(-a.x, a.y);
}

}  // namespace

TEST_CASE("a ball-tumbler hit honours its restitution with the rolling tumbler's response", "[sim][world]") {
    // The tumbler rolls on the floor, so it answers a hit with its constrained effective
    // mass (the floor supplies the rest of the impulse: linear momentum is not kept, the
    // floor takes some). Checked: the relative normal velocity at the contact point
    // becomes exactly −e times what it was, the tumbler's new velocity satisfies the
    // rolling constraint (its floor contact point is at rest), and for e = 1 the kinetic
    // energy of ball + tumbler (½m_b v² + ½ωᵀAω, A the inertia about the contact point)
    // is kept. 1e-12: one impulse, a handful of roundings on O(1) numbers.
    for (double e : {1.0, 0.5, 0.0}) {
        Scene s = emptyScene();
        s.physics.restitution.ballTumbler = e;
        s.tumblers.push_back({{0.0, 0.0}, {0.0, 0.1}, {1, 0, 0}});
        World w(s);
        w.tumblers()[0].angularVelocity = Vec3(0.3, 0.5, -0.4);  // rolling, spinning, rocking
        w.tumblers()[0].velocity = 0.2 * Vec3(0.4, 0.0, 0.3);
        // A marble overlapping the lower sphere at O's height, moving into it (the push
        // out is then horizontal and costs no height, so its speed is left alone).
        w.spawnMarble(Vec3(-0.22, -0.8, 0.02), Vec3(3.0, 0.5, -0.2));
        const Ball& ball = w.balls()[0];
        const Vec3 half(0, 0.5 * s.physics.gravity * s.physics.dt / s.physics.substeps, 0);
        auto midStep = [&] { return ball.velocity - half; };
        auto kinetic = [&] {
            const Vec3& om = w.tumblers()[0].angularVelocity;
            const Vec3 u = midStep();
            return 0.5 * ball.mass() * glm::dot(u, u) + 0.5 * glm::dot(om, w.rollingInertia(0) * om);
        };
        // Where the contact will be: the resolve pushes the ball out first, along n.
        const double d = w.tumblerSdf(0, ball.position);
        const Vec3 n = w.tumblerNormal(0, ball.position), h = ball.position - d * n;
        const double vnBefore = glm::dot(midStep() - w.pointVelocity(0, h), n);
        const double e0 = kinetic();
        REQUIRE(vnBefore < -1.0);
        REQUIRE(w.resolveBallTumblerContact(0, 0));
        const double vnAfter = glm::dot(midStep() - w.pointVelocity(0, h), n);
        INFO("e = " << e << ": vn " << vnBefore << " -> " << vnAfter);
        CHECK(vnAfter == Approx(-e * vnBefore).margin(1e-12));
        CHECK(glm::length(w.pointVelocity(0, w.floorContact(0))) < 1e-12);
        if (e == 1.0) CHECK(std::abs(kinetic() - e0) / e0 < 1e-12);
        else CHECK(kinetic() < e0);
    }
}

TEST_CASE("a marble bouncing 1e5 steps keeps its modified energy E' exactly", "[sim][world]") {
    // E′ = ½|v|² + g·y − ½·g·Δt·v_y is what semi-implicit Euler conserves in free flight;
    // the time-symmetric bounce (v₁ = −v₀, x₁ = x₀ + v₁Δt) conserves it across walls.
    // Only rounding remains: ~1e-16 per operation, a random walk over 1e5 steps and
    // a few hundred bounces stays far below 1e-10 relative; 1e-10 is the bound.
    for (BallKind kind : {BallKind::Marble, BallKind::Fireball}) {
        Scene s = emptyScene();
        // Stays below the lamp dome (y ≤ 0.53 < 0.70) so only the walls act.
        auto& list = kind == BallKind::Marble ? s.marbles : s.fireballs;
        list.push_back({{0.1, 0.5, -0.2}, {1.3, 0.7, 0.9}, 0.05, {1, 1, 1}});
        if (kind == BallKind::Fireball) list.back().velocity = {1.3, -0.1, 0.9};
        World w(s);
        const double e0 = w.ballEnergy(0);
        const int frames = 100000 / s.physics.substeps / kScale;
        double worst = 0;
        int bounces = 0;
        Vec3 lastV = w.balls()[0].velocity;
        for (int i = 0; i < frames; ++i) {
            w.step();
            worst = std::max(worst, std::abs(w.ballEnergy(0) - e0) / e0);
            const Vec3 v = w.balls()[0].velocity;
            for (int k = 0; k < 3; k += 2) bounces += (v[k] > 0) != (lastV[k] > 0);
            lastV = v;
        }
        INFO((kind == BallKind::Marble ? "marble" : "fireball") << ": worst relative E' error " << worst << " over "
                                                                << bounces << " side-wall bounces");
        CHECK(bounces > 50 / kScale);  // really bounced (kScale: fewer steps under sanitizers)
        CHECK(worst < 1e-10);
        CHECK(w.maxContainmentViolation() <= 0.0);
    }
}

TEST_CASE("accurate mode: the small rocking period matches 2π/ω₀ within 1 %", "[sim][world]") {
    Scene s = emptyScene();
    s.physics.tumblerMode = TumblerMode::Accurate;
    s.physics.ballastH = 0.05;
    s.tumblers.push_back({{0.0, 0.0}, {0.0, 0.05}, {1, 0, 0}});
    World w(s);
    const double m = 1.0, g = s.physics.gravity, h = 0.05, b = 0.2;
    const double ic = w.massProperties().inertiaCom.x;
    const double expected = 2.0 * M_PI * std::sqrt((ic + m * (b - h) * (b - h)) / (m * g * h));
    REQUIRE(expected == Approx(1.94025).epsilon(1e-4));  // docs/physics.md's value
    // Upward zero crossings of the tilt; the period is their mean spacing.
    std::vector<double> crossings;
    double prev = tiltAboutZ(w.tumblers()[0]);
    while (w.time() < 8.0) {
        w.step();
        double now = tiltAboutZ(w.tumblers()[0]);
        if (prev < 0 && now >= 0) crossings.push_back(w.time() - s.physics.dt * now / (now - prev));
        prev = now;
    }
    REQUIRE(crossings.size() >= 3);
    const double period = (crossings.back() - crossings.front()) / double(crossings.size() - 1);
    INFO("period " << period << " s, expected " << expected << " s");
    CHECK(std::abs(period - expected) / expected < 0.01);
}

TEST_CASE("a uniform tumbler tilted 5 degrees falls over, a ballasted one rights itself", "[sim][world]") {
    for (bool ballasted : {false, true}) {
        Scene s = emptyScene();
        s.physics.tumblerMode = TumblerMode::Accurate;
        // Rolling friction: its constant deceleration μg/b must stay below gravity's
        // torque at 5° (0.5 rad/s² for the uniform toy), or friction holds it up.
        s.physics.friction = 0.005;
        // Uniform: the centre of mass 0.0521 above O (docs/physics.md §2).
        s.physics.ballastH = ballasted ? 0.05 : -0.0521160345185;
        s.tumblers.push_back({{0.0, 0.0}, {0.0, 5.0 * M_PI / 180.0}, {1, 0, 0}});
        World w(s);
        double maxTilt = 0;
        while (w.time() < 3.0) {
            w.step();
            maxTilt = std::max(maxTilt, std::abs(tiltAboutZ(w.tumblers()[0])));
        }
        INFO((ballasted ? "ballasted" : "uniform") << ": max tilt " << maxTilt);
        if (ballasted) CHECK(maxTilt < 6.0 * M_PI / 180.0);   // never beyond its start (+1° slack)
        else CHECK(maxTilt > 60.0 * M_PI / 180.0);            // it goes down
    }
}

TEST_CASE("stress: long runs, many balls, fast bodies, extreme dt stay finite and contained", "[sim][world][stress]") {
    // Checked after every frame, not just at the end. Bounds: containment is exact per
    // sphere (walls push and clamp every sub-step), so 1e-9 m is rounding only;
    // quaternions are renormalised every sub-step, so 1e-6 is generous (seen: 4e-16).
    auto check = [](const World& w, const char* what) {
        INFO(what << " at t = " << w.time());
        REQUIRE(w.allFinite());
        REQUIRE(w.maxContainmentViolation() < 1e-9);
        REQUIRE(w.maxQuaternionError() < 1e-6);
    };
    auto run = [&](World& w, int frames, const char* what) {
        for (int i = 0; i < frames; ++i) {
            w.step();
            check(w, what);
        }
    };
    SECTION("1e6 sub-steps of the default scene") {
        // 250 000 frames × 4 sub-steps = 1e6 sub-steps (17 min of simulated time); a
        // tenth under sanitizers (KILN_SANITIZED_BUILD).
        World w(shippedScene());
        run(w, 250000 / kScale, "default scene");
        CHECK(w.particles().size() <= 4096);
    }
    SECTION("200 marbles") {
        World w(shippedScene());
        for (int i = 0; i < 200; ++i) w.spawnRandom(BallKind::Marble);
        run(w, 2000 / kScale, "200 marbles");
    }
    SECTION("fireballs at 50 m/s do not tunnel") {
        Scene s = shippedScene();
        s.fireballs.push_back({{0.0, 0.3, 0.0}, {50.0, 20.0, -35.0}, 0.06, {1, 0.5, 0}});
        World w(s);
        run(w, 5000 / kScale, "fast fireball");
    }
    SECTION("a 50 m/s fireball at dt = 1/30 does not jump over a tumbler") {
        Scene s = emptyScene();
        s.physics.dt = 1.0 / 30;
        s.physics.substeps = 1;
        s.physics.maxSubsteps = 1;  // no adaptive sub-steps: the swept test alone
        s.tumblers.push_back({{0.0, 0.0}, {0.0, 0.0}, {1, 0, 0}});
        s.fireballs.push_back({{-0.8, -0.75, 0.0}, {50.0, 0.0, 0.0}, 0.06, {1, 0.5, 0}});
        World w(s);
        w.step();  // 1.67 m in one step: from x = −0.8 it would land at +0.87, past the toy
        INFO("fireball at x = " << w.balls()[0].position.x << ", v_x = " << w.balls()[0].velocity.x);
        CHECK(w.balls()[0].position.x < -0.2);  // stopped at the tumbler's near side
        CHECK(w.balls()[0].velocity.x < 50.0);  // and the impulse acted
        check(w, "swept fireball");
    }
    SECTION("dt from 1/1000 to 1/30") {
        for (double dt : {1.0 / 1000, 1.0 / 240, 1.0 / 60, 1.0 / 30}) {
            Scene s = shippedScene();
            s.physics.dt = dt;
            s.physics.substeps = 1;
            World w(s);
            run(w, 3000 / kScale, "extreme dt");
        }
    }
    SECTION("coincident bodies") {
        Scene s = emptyScene();
        s.tumblers.push_back({{0.1, 0.1}, {0, 0}, {1, 0, 0}});
        s.tumblers.push_back({{0.1, 0.1}, {0, 0}, {0, 1, 0}});
        s.marbles.push_back({{0.3, 0.3, 0.3}, {0, 0, 0}, 0.05, {1, 1, 1}});
        s.marbles.push_back({{0.3, 0.3, 0.3}, {0, 0, 0}, 0.05, {1, 1, 1}});
        World w(s);
        run(w, 1000, "coincident");
        CHECK(glm::length(w.tumblers()[0].position - w.tumblers()[1].position) > 0.3);  // pushed apart
    }
    SECTION("balls exactly on a tumbler's axis and at its sphere centres; singular K") {
        Scene s = emptyScene();
        s.tumblers.push_back({{0.0, 0.0}, {0, 0}, {1, 0, 0}});
        World w(s);
        // Inside, on the axis (no unique normal: the +y fallback), at O and at the
        // upper centre (gradient of a sphere at its centre).
        w.spawnMarble(Vec3(0.0, -0.7, 0.0), Vec3(0.0, -1.0, 0.0));
        w.spawnMarble(Vec3(0.0, -0.8, 0.0), Vec3(0.0));
        w.spawnMarble(w.tumblers()[0].upperCentre(w.shape()), Vec3(0.0));
        run(w, 500, "on-axis balls");
        for (int i = 0; i < 3; ++i)  // all pushed out of the toy
            CHECK(w.tumblerSdf(0, w.balls()[size_t(i)].position) > w.balls()[size_t(i)].radius - 1e-3);
        // A contact at the centre of mass (r = 0: K = 𝟙/m, no angular part) and a
        // zero impulse; the singular-K solve itself is tested in test_contact.cpp.
        w.applyImpulse(0, w.centreOfMass(0), Vec3(0.0, 0.0, 0.0));
        check(w, "zero impulse at the centre of mass");
    }
}

TEST_CASE("determinism: same scene and seed give the same hash, another seed differs", "[sim][world]") {
    auto run = [](uint64_t seed) {
        Scene s = shippedScene();
        s.physics.seed = seed;
        World w(s);
        for (int i = 0; i < 1500; ++i) w.step();
        return w.stateHash();
    };
    const uint64_t h1 = run(1);
    CHECK(h1 == run(1));
    CHECK(h1 != run(2));
    // A stored value: the same on every build (RelWithDebInfo and the sanitized Debug
    // build agree: both compile with -std=c++20, which disables FP contraction, and the
    // sim uses no library function whose result may differ between them). It changes
    // whenever the dynamics change on purpose. To regenerate: run this test, read the
    // "hash" line of its output (or `kiln-sim run --steps 1500 --seed 1`, whose hash is
    // the same scene, seed and step count) and paste it here.
    INFO("hash " << std::hex << h1);
    CHECK(h1 == kCornellHash1500);
}

TEST_CASE("a paused or fully asleep world does not bump the body version", "[sim][world]") {
    Scene s = emptyScene();
    s.physics.friction = 2.0;
    s.tumblers.push_back({{0.0, 0.0}, {0.0, 0.0}, {1, 0, 0}});
    World w(s);
    for (int i = 0; i < 600; ++i) w.step();  // 2.5 s: long enough to fall asleep
    REQUIRE(w.tumblers()[0].asleep);
    const uint64_t v = w.bodiesVersion();
    w.step();
    CHECK(w.bodiesVersion() == v);
    w.spawnMarble(Vec3(0.5, 0.5, 0.5), Vec3(0.0));
    w.step();
    CHECK(w.bodiesVersion() > v);
}

TEST_CASE("picking: the ray through a tumbler hits it, drags translate and rotate", "[sim][world][picking]") {
    Scene s = emptyScene();
    s.tumblers.push_back({{-0.4, 0.0}, {0, 0}, {1, 0, 0}});
    s.tumblers.push_back({{0.4, 0.0}, {0, 0}, {0, 1, 0}});
    World w(s);
    const Vec3 eye(0.0, 0.0, 3.9);
    // Through the second tumbler's lower-sphere centre: hit it, not the first.
    auto hit = w.raycastTumblers(eye, w.tumblers()[1].position - eye);
    REQUIRE(hit);
    CHECK(hit->tumbler == 1);
    CHECK(std::abs(w.tumblerSdf(1, hit->point)) < 1e-4);
    CHECK_FALSE(w.raycastTumblers(eye, Vec3(0.0, 1.0, -0.2)));  // over everyone's head

    SECTION("below the centre of mass: translate to the plane point") {
        auto low = w.raycastTumblers(eye, w.tumblers()[1].position + Vec3(0, -0.1, 0) - eye);
        REQUIRE(low);
        REQUIRE(w.beginDrag(*low) == DragMode::Translate);
        const Vec3 offset = low->point - w.tumblers()[1].position;
        // A ray to a point on the drag plane 0.2 further along +x and -z.
        const Vec3 target = low->point + Vec3(0.2, 0.0, -0.2);
        w.dragTo(eye, target - eye);
        CHECK(w.tumblers()[1].position.x == Approx(target.x - offset.x).margin(1e-9));
        CHECK(w.tumblers()[1].position.z == Approx(target.z - offset.z).margin(1e-9));
        w.endDrag();
    }
    SECTION("above: rotate and roll the matching distance") {
        auto high = w.raycastTumblers(eye, w.tumblers()[1].upperCentre(w.shape()) - eye);
        REQUIRE(high);
        REQUIRE(w.beginDrag(*high) == DragMode::Rotate);
        const double x0 = w.tumblers()[1].position.x;
        w.dragRotate(0.0, 0.3);
        CHECK(tiltAboutZ(w.tumblers()[1]) == Approx(0.3).margin(1e-12));
        CHECK(w.tumblers()[1].position.x == Approx(x0 - 0.2 * 0.3).margin(1e-12));  // −b·θ
        w.endDrag();
    }
}

TEST_CASE("exact tumbler separation: known poses", "[sim][world]") {
    // Two upright tumblers 0.5 apart: the lower spheres are closest, 0.5 − 0.4 = 0.1.
    RoundCone s;
    const Vec3 up(0, s.upperCentre(), 0);
    auto sep = roundConeSeparation(Vec3(0.0), up, 0.2, 0.1, Vec3(0.5, 0, 0), Vec3(0.5, 0, 0) + up, 0.2, 0.1);
    CHECK(sep.distance == Approx(0.1).margin(1e-9));
    // Overlapping by 5 cm.
    sep = roundConeSeparation(Vec3(0.0), up, 0.2, 0.1, Vec3(0.35, 0, 0), Vec3(0.35, 0, 0) + up, 0.2, 0.1);
    CHECK(sep.distance == Approx(-0.05).margin(1e-9));
}

TEST_CASE("accurate mode: the period at 30 degrees matches the exact quadrature", "[sim][world]") {
    // docs/physics.md §3: T(30°) = 2.00225 s for h = 0.05 (from the full nonlinear equation).
    // 1 %: the integrator's period error is second order, −(ωΔt)²/24 ≈ 1e-5 here; the
    // rest is the zero-crossing interpolation (≤ Δt/T ≈ 0.2 % per crossing, averaged).
    Scene s = emptyScene();
    s.physics.tumblerMode = TumblerMode::Accurate;
    s.physics.ballastH = 0.05;
    s.tumblers.push_back({{0.0, 0.0}, {0.0, 30.0 * M_PI / 180.0}, {1, 0, 0}});
    World w(s);
    std::vector<double> crossings;
    double prev = tiltAboutZ(w.tumblers()[0]);
    while (w.time() < 9.0) {
        w.step();
        const double now = tiltAboutZ(w.tumblers()[0]);
        if (prev < 0 && now >= 0) crossings.push_back(w.time() - s.physics.dt * now / (now - prev));
        prev = now;
    }
    REQUIRE(crossings.size() >= 3);
    const double period = (crossings.back() - crossings.front()) / double(crossings.size() - 1);
    INFO("period " << period << " s, expected 2.00225 s");
    CHECK(std::abs(period - 2.00225) / 2.00225 < 0.01);
}

TEST_CASE("course mode: the restoring impulse rights a tilted tumbler", "[sim][world]") {
    Scene s = emptyScene();
    s.physics.tumblerMode = TumblerMode::Course;
    s.physics.friction = 0.05;
    s.tumblers.push_back({{0.0, 0.0}, {0.3, 0.0}, {1, 0, 0}});
    World w(s);
    for (int i = 0; i < 240 * 20; ++i) w.step();
    const Tumbler& t = w.tumblers()[0];
    const double tilt = std::acos(std::clamp(t.axis().y, -1.0, 1.0));
    INFO("tilt after 20 s " << tilt << " rad");
    CHECK(tilt < 0.05);                                       // back upright (from 0.3 rad)
    CHECK(t.position.y == Approx(-1.0 + 0.2).margin(1e-12));  // still on the floor
}

TEST_CASE("tumblers: walls turn them back, a uniform one lies on its side", "[sim][world]") {
    SECTION("rocking into the +x wall") {
        Scene s = emptyScene();
        s.tumblers.push_back({{0.6, 0.0}, {0.0, 0.0}, {1, 0, 0}});
        World w(s);
        // Rolling towards +x (v_x = −b·ω_z) tilts it towards the wall as well.
        w.tumblers()[0].angularVelocity = Vec3(0, 0, -10.0);
        w.tumblers()[0].velocity = Vec3(2.0, 0, 0);
        double maxUpperX = -1;
        bool reversed = false;
        for (int i = 0; i < 240; ++i) {
            w.step();
            maxUpperX = std::max(maxUpperX, w.tumblers()[0].upperCentre(w.shape()).x);
            reversed = reversed || w.tumblers()[0].angularVelocity.z > 0.0;
            // Containment is exact per sphere (the pushes run every sub-step); 1e-12 m
            // is rounding of the push.
            REQUIRE(w.maxContainmentViolation() < 1e-12);
        }
        INFO("max upper-sphere x " << maxUpperX);
        CHECK(maxUpperX > 0.88);  // it reached the wall (limit 1 − t = 0.9; sampled per frame)
        CHECK(reversed);                // and was turned back
    }
    SECTION("uniform density: it falls and rests on the upper sphere (≈110°)") {
        Scene s = emptyScene();
        s.physics.tumblerMode = TumblerMode::Accurate;
        s.physics.ballastH = -0.0521160345185;
        s.tumblers.push_back({{0.0, 0.0}, {0.0, 5.0 * M_PI / 180.0}, {1, 0, 0}});
        World w(s);
        for (int i = 0; i < 240 * 4; ++i) w.step();
        const Tumbler& t = w.tumblers()[0];
        const double tilt = std::acos(std::clamp(t.axis().y, -1.0, 1.0));
        const double lying = std::acos((0.1 - 0.2) / w.shape().upperCentre());  // upper sphere on the floor
        INFO("tilt " << tilt * 180 / M_PI << " deg, lying " << lying * 180 / M_PI << " deg");
        // 1°: the floor contact is resolved each sub-step by rotating back onto the floor.
        CHECK(std::abs(tilt - lying) < M_PI / 180.0);
        CHECK(t.upperCentre(w.shape()).y - 0.1 > -1.0 - 1e-9);
        CHECK(w.allFinite());
        CHECK(t.asleep);  // lying still: it sleeps (costs nothing) until something hits it
    }
}

TEST_CASE("tumbler against tumbler: both methods push them apart", "[sim][world]") {
    for (TumblerContact method : {TumblerContact::FourSpheres, TumblerContact::Exact}) {
        Scene s = emptyScene();
        s.physics.tumblerContact = method;
        s.tumblers.push_back({{-0.25, 0.0}, {0.0, -0.3}, {1, 0, 0}});
        s.tumblers.push_back({{0.25, 0.0}, {0.0, 0.3}, {0, 1, 0}});
        World w(s);
        // Roll them into each other.
        w.tumblers()[0].angularVelocity = Vec3(0, 0, -5.0), w.tumblers()[0].velocity = Vec3(1.0, 0, 0);
        w.tumblers()[1].angularVelocity = Vec3(0, 0, 5.0), w.tumblers()[1].velocity = Vec3(-1.0, 0, 0);
        double worst = 0;
        for (int i = 0; i < 480; ++i) {
            w.step();
            worst = std::min(worst, w.deepestTumblerOverlap());
        }
        INFO((method == TumblerContact::Exact ? "exact" : "four spheres") << ": deepest overlap after a step " << worst);
        REQUIRE(w.allFinite());
        // Exact: pushed apart within the step that found the overlap, so only the
        // sub-steps' motion after the push remains (≤ |v|·Δt ≈ 5 mm). The four-sphere
        // test misses side-on-side overlaps (docs/physics.md §4: centimetres).
        CHECK(worst > (method == TumblerContact::Exact ? -0.005 : -0.04));
        CHECK(w.tumblers()[0].position.x < w.tumblers()[1].position.x);
    }
}

TEST_CASE("two marbles collide elastically: momentum and energy kept", "[sim][world]") {
    Scene s = emptyScene();
    World w(s);
    w.spawnMarble(Vec3(0.0, 0.0, 0.0), Vec3(1.0, 0.2, -0.3), 0.05);
    w.spawnMarble(Vec3(0.08, 0.03, 0.0), Vec3(-0.5, 0.0, 0.4), 0.07);
    auto& a = w.balls()[0];
    auto& b = w.balls()[1];
    const Vec3 p0 = a.mass() * a.velocity + b.mass() * b.velocity;
    const double e0 = 0.5 * a.mass() * glm::dot(a.velocity, a.velocity) + 0.5 * b.mass() * glm::dot(b.velocity, b.velocity);
    REQUIRE(w.resolveBallBallContact(0, 1));
    const Vec3 p1 = a.mass() * a.velocity + b.mass() * b.velocity;
    const double e1 = 0.5 * a.mass() * glm::dot(a.velocity, a.velocity) + 0.5 * b.mass() * glm::dot(b.velocity, b.velocity);
    // 1e-12 relative: one impulse, a few roundings.
    CHECK(glm::length(p1 - p0) / glm::length(p0) < 1e-12);
    CHECK(std::abs(e1 - e0) / e0 < 1e-12);
    CHECK(glm::length(b.position - a.position) == Approx(0.12).epsilon(1e-12));  // just touching
    // Coincident centres: separated along x, no NaN.
    w.spawnMarble(Vec3(0.5, 0.5, 0.5), Vec3(0.0), 0.05);
    w.spawnMarble(Vec3(0.5, 0.5, 0.5), Vec3(0.0), 0.05);
    REQUIRE(w.resolveBallBallContact(2, 3));
    CHECK(w.allFinite());
    CHECK(w.balls()[3].position.x - w.balls()[2].position.x == Approx(0.1).epsilon(1e-12));
}

TEST_CASE("discrete free fall is exactly y_n = y0 + n dt v0 - g dt^2 n(n+1)/2", "[sim][world]") {
    Scene s = emptyScene();
    s.physics.substeps = 1;
    s.marbles.push_back({{0.7, 0.9, 0.0}, {0.0, 0.5, 0.0}, 0.05, {1, 1, 1}});  // beside the lamp
    World w(s);
    const double dt = s.physics.dt, g = s.physics.gravity;
    for (int n = 1; n <= 100; ++n) {  // 0.42 s: 0.9 + 0.21 − 0.89 > −0.95, no bounce yet
        w.step();
        const double y = 0.9 + n * dt * 0.5 - g * dt * dt * n * (n + 1) / 2.0;
        // 1e-12 m: rounding of 100 additions of O(1) numbers.
        REQUIRE(w.balls()[0].position.y == Approx(y).margin(1e-12));
    }
}

TEST_CASE("sleeping tumblers wake when a marble lands on them", "[sim][world]") {
    Scene s = emptyScene();
    s.physics.friction = 2.0;
    s.tumblers.push_back({{0.0, 0.0}, {0.0, 0.0}, {1, 0, 0}});
    World w(s);
    for (int i = 0; i < 600; ++i) w.step();
    REQUIRE(w.tumblers()[0].asleep);
    const uint64_t hash = w.stateHash();
    w.step();
    CHECK(w.stateHash() != hash);  // time advances, but the body did not move:
    CHECK(w.tumblers()[0].velocity == Vec3(0.0));
    w.spawnMarble(Vec3(0.05, 0.0, 0.0), Vec3(0.0, -3.0, 0.0));
    bool woke = false;
    for (int i = 0; i < 120 && !woke; ++i) {
        w.step();
        woke = !w.tumblers()[0].asleep;
    }
    CHECK(woke);
}

TEST_CASE("determinism with inputs: drags and spawns replay bit-identically", "[sim][world]") {
    auto run = [] {
        World w(shippedScene());
        for (int i = 0; i < 300; ++i) {
            w.step();
            if (i == 50) w.spawnRandom(BallKind::Marble);
            if (i == 60) w.spawnRandom(BallKind::Fireball);
            if (i == 100) {
                auto hit = w.raycastTumblers(Vec3(0, 0, 3.9), w.tumblers()[2].position - Vec3(0, 0, 3.9));
                REQUIRE(hit);
                w.beginDrag(*hit);
            }
            if (i > 100 && i < 140) w.dragRotate(0.01, -0.01);
            if (i == 140) w.endDrag();
        }
        return w.stateHash();
    };
    CHECK(run() == run());
}

TEST_CASE("a tumbler's model matrix maps its local frame to the world", "[sim][world]") {
    // The host builds its instance records from Tumbler::modelMatrix (float, column-major).
    World w(shippedScene());
    for (int i = 0; i < 100; ++i) w.step();
    for (const Tumbler& t : w.tumblers()) {
        float m[16];
        t.modelMatrix(m);
        // Float precision (≈ 6e-8 relative on O(1) numbers) is what the GPU gets: 1e-6.
        for (const Vec3 local : {Vec3(0.1, 0.2, -0.05), Vec3(0.0, w.shape().top(), 0.0), Vec3(-0.2, 0.0, 0.0)}) {
            const Vec3 world = t.position + t.orientation * local;
            for (int r = 0; r < 3; ++r)
                CHECK(m[r] * local.x + m[4 + r] * local.y + m[8 + r] * local.z + m[12 + r] == Approx(world[r]).margin(1e-6));
        }
        CHECK(m[3] == 0.0f);
        CHECK(m[7] == 0.0f);
        CHECK(m[11] == 0.0f);
        CHECK(m[15] == 1.0f);
    }
}

TEST_CASE("the shipped scene's tumblers rock and right themselves while the balls keep moving", "[sim][world]") {
    // What a roly-poly toy does: knocked by the balls it rocks, and never stays down.
    // Over the first 30 s no tumbler lies on its side (its axis past horizontal, where the
    // upper sphere meets the floor), and over the last 10 of them the mean tilt is small.
    const Scene s = shippedScene();
    World w(s);
    const int frames = int(std::lround(30.0 / s.physics.dt)), lateFrom = int(std::lround(20.0 / s.physics.dt));
    double worst = 0.0, lateSum = 0.0;
    int lateSamples = 0;
    for (int f = 0; f < frames; ++f) {
        w.step();
        for (const Tumbler& t : w.tumblers()) {
            const double tilt = std::acos(std::clamp(t.axis().y, -1.0, 1.0)) * 180.0 / M_PI;
            worst = std::max(worst, tilt);
            if (f >= lateFrom) lateSum += tilt, ++lateSamples;
        }
    }
    const double lateMean = lateSum / lateSamples;
    INFO("largest tilt " << worst << "°, mean over the last 10 s " << lateMean << "°");
    CHECK(worst < 90.0);
    CHECK(lateMean < 15.0);
    // The balls left (fire turns marbles to ash) still move: a ball leaves a tumbler at the
    // speed it came, and nothing else they touch takes energy.
    double speed = 0.0;
    for (const Ball& b : w.balls()) speed += glm::length(b.velocity);
    CHECK(speed / double(w.balls().size()) > 0.3);
}
