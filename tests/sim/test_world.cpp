// The world: impulses, energy, rocking, stress, determinism, picking.
#include <catch2/catch.hpp>

#include <cmath>

#include "kiln/sim/world.hpp"

using namespace kiln::sim;

namespace {

#ifdef KILN_SANITIZED_BUILD
constexpr int kScale = 10;
#else
constexpr int kScale = 1;
#endif

Scene emptyScene() {
    Scene s;
    s.physics.friction = 0.0;
    return s;
}

Scene defaultScene() {
    Scene s;
    std::string error;
    REQUIRE(loadScene(std::string(KILN_SOURCE_DIR) + "/scenes/cornell.json", s, error));
    return s;
}

double tiltAboutZ(const Tumbler& t) {
    const Vec3 a = t.axis();
    return std::atan2(-a.x, a.y);
}

}  // namespace

TEST_CASE("a ball-tumbler impulse conserves linear momentum and energy", "[sim][world]") {
    Scene s = emptyScene();
    s.tumblers.push_back({{0.0, 0.0}, {0.0, 0.0}, {1, 0, 0}});
    World w(s);
    // A marble overlapping the tumbler's side, moving into it.
    w.spawnMarble(Vec3(-0.22, -0.8, 0.02), Vec3(3.0, 0.5, -0.2));
    Ball& ball = w.balls()[0];
    auto momentum = [&] {
        const Tumbler& t = w.tumblers()[0];
        Vec3 vG = t.velocity + glm::cross(t.angularVelocity, w.centreOfMass(0) - t.position);
        return ball.mass() * ball.velocity + w.tumblerMass() * vG;
    };
    auto energy = [&] {
        const Tumbler& t = w.tumblers()[0];
        Vec3 vG = t.velocity + glm::cross(t.angularVelocity, w.centreOfMass(0) - t.position);
        Mat3 r = t.rotation();
        Vec3 wl = glm::transpose(r) * t.angularVelocity;
        const Vec3 I = w.massProperties().inertiaCom;
        return 0.5 * ball.mass() * glm::dot(ball.velocity, ball.velocity) + 0.5 * w.tumblerMass() * glm::dot(vG, vG) +
               0.5 * (I.x * wl.x * wl.x + I.y * wl.y * wl.y + I.z * wl.z * wl.z);
    };
    const Vec3 p0 = momentum();
    const double e0 = energy();
    REQUIRE(w.resolveBallTumblerContact(0, 0));
    const Vec3 p1 = momentum();
    // 1e-9 relative: a handful of double operations on O(1) numbers.
    CHECK(glm::length(p1 - p0) / glm::length(p0) < 1e-9);
    CHECK(std::abs(energy() - e0) / e0 < 1e-9);
    CHECK(glm::length(ball.velocity - Vec3(3.0, 0.5, -0.2)) > 0.1);  // something really happened
}

TEST_CASE("a marble bouncing 1e5 steps keeps its energy: bounded swings, no trend", "[sim][world]") {
    Scene s = emptyScene();
    s.marbles.push_back({{0.1, 0.5, -0.2}, {1.3, 0.7, 0.9}, 0.05, {1, 1, 1}});
    World w(s);
    const double g = s.physics.gravity;
    auto energy = [&] {
        const Ball& b = w.balls()[0];
        return 0.5 * glm::dot(b.velocity, b.velocity) + g * b.position.y;
    };
    const double e0 = energy();
    const int frames = 100000 / s.physics.substeps / kScale;
    double worst = 0, early = 0, late = 0;
    for (int i = 0; i < frames; ++i) {
        w.step();
        const double rel = (energy() - e0) / e0;
        worst = std::max(worst, std::abs(rel));
        if (i < frames / 10) early += rel / (frames / 10);
        if (i >= frames - frames / 10) late += rel / (frames / 10);
    }
    INFO("worst " << worst << ", mean early " << early << ", mean late " << late);
    // Penetrate-then-mirror bounces move the energy by O(g·|v|·dt) per bounce, both
    // ways (measured: within ±0.6 %); 2 % bounds the swings and 0.5 % the trend.
    CHECK(worst < 0.02);
    CHECK(std::abs(late - early) < 0.005);
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
    REQUIRE(expected == Approx(1.94025).epsilon(1e-4));  // PHYSICS.md's value
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

TEST_CASE("a uniform tumbler tilted 5 degrees falls over; a ballasted one rights itself", "[sim][world]") {
    for (bool ballasted : {false, true}) {
        Scene s = emptyScene();
        s.physics.tumblerMode = TumblerMode::Accurate;
        // Rolling friction: its constant deceleration μg/b must stay below gravity's
        // torque at 5° (0.5 rad/s² for the uniform toy), or friction holds it up.
        s.physics.friction = 0.005;
        // Uniform: the centre of mass 0.0521 above O (PHYSICS.md).
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
    auto check = [](const World& w, const char* what) {
        INFO(what);
        REQUIRE(w.allFinite());
        // 1e-9 m: containment is exact per sphere up to rounding of the clamps.
        CHECK(w.maxContainmentViolation() < 1e-9);
        CHECK(w.maxQuaternionError() < 1e-6);
    };
    SECTION("1e6 sub-steps of the default scene") {
        World w(defaultScene());
        for (int i = 0; i < 250000 / kScale; ++i) w.step();
        check(w, "default scene");
        CHECK(w.particles().size() <= 4096);
    }
    SECTION("200 marbles") {
        World w(defaultScene());
        for (int i = 0; i < 200; ++i) w.spawnRandom(BallKind::Marble);
        for (int i = 0; i < 2000 / kScale; ++i) w.step();
        check(w, "200 marbles");
    }
    SECTION("fireballs at 50 m/s do not tunnel") {
        Scene s = defaultScene();
        s.fireballs.push_back({{0.0, 0.3, 0.0}, {50.0, 20.0, -35.0}, 0.06, {1, 0.5, 0}});
        World w(s);
        for (int i = 0; i < 5000 / kScale; ++i) w.step();
        check(w, "fast fireball");
    }
    SECTION("dt from 1/1000 to 1/30") {
        for (double dt : {1.0 / 1000, 1.0 / 240, 1.0 / 60, 1.0 / 30}) {
            Scene s = defaultScene();
            s.physics.dt = dt;
            s.physics.substeps = 1;
            World w(s);
            for (int i = 0; i < 3000 / kScale; ++i) w.step();
            check(w, "extreme dt");
        }
    }
    SECTION("coincident bodies") {
        Scene s = emptyScene();
        s.tumblers.push_back({{0.1, 0.1}, {0, 0}, {1, 0, 0}});
        s.tumblers.push_back({{0.1, 0.1}, {0, 0}, {0, 1, 0}});
        s.marbles.push_back({{0.3, 0.3, 0.3}, {0, 0, 0}, 0.05, {1, 1, 1}});
        s.marbles.push_back({{0.3, 0.3, 0.3}, {0, 0, 0}, 0.05, {1, 1, 1}});
        World w(s);
        for (int i = 0; i < 1000; ++i) w.step();
        check(w, "coincident");
        CHECK(glm::length(w.tumblers()[0].position - w.tumblers()[1].position) > 0.3);  // pushed apart
    }
    SECTION("a ball exactly on a tumbler's axis, and a singular contact") {
        Scene s = emptyScene();
        s.tumblers.push_back({{0.0, 0.0}, {0, 0}, {1, 0, 0}});
        World w(s);
        w.spawnMarble(Vec3(0.0, -0.7, 0.0), Vec3(0.0, -1.0, 0.0));  // inside, on the axis
        for (int i = 0; i < 500; ++i) w.step();
        check(w, "on-axis ball");
        // K = (1/m)𝟙 − [r]×I⁻¹[r]× with r = 0 (contact at the centre of mass).
        w.applyImpulse(0, w.centreOfMass(0), Vec3(0.0, 0.0, 0.0));
        check(w, "zero impulse at the centre of mass");
    }
}

TEST_CASE("determinism: same scene and seed give the same hash; another seed differs", "[sim][world]") {
    auto run = [](uint64_t seed) {
        Scene s = defaultScene();
        s.physics.seed = seed;
        World w(s);
        for (int i = 0; i < 1500; ++i) w.step();
        return w.stateHash();
    };
    CHECK(run(1) == run(1));
    CHECK(run(1) != run(2));
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

TEST_CASE("picking: the ray through a tumbler hits it; drags translate and rotate", "[sim][world][picking]") {
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
