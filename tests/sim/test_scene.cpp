// Bad scene files: each error names the JSON path and what is wrong.
#include <catch2/catch.hpp>

#include <chrono>
#include <cmath>
#include <cstdio>

#include "kiln/sim/scene.hpp"
#include "kiln/sim/world.hpp"

using namespace kiln::sim;

namespace {
std::string errorOf(const std::string& text) {
    Scene s;
    SceneError e;
    REQUIRE_FALSE(parseScene(text, s, e));
    return e.toString("scenes/x.json");
}
}  // namespace

TEST_CASE("the shipped scene loads", "[sim][scene]") {
    Scene s;
    std::string error;
    REQUIRE(loadScene(std::string(KILN_SOURCE_DIR) + "/scenes/cornell.json", s, error));
    CHECK(s.tumblers.size() == 5);
    CHECK(s.fireballs.size() == 2);
    CHECK(s.lamp.center.y > 1.0);  // the light sits outside the box
    // It states how every contact kind behaves: the balls' bounces off the box elastic and
    // their speed kept off the tumblers; the tumblers' knocks and rocking damped.
    CHECK(s.physics.restitution.ballBox == 1.0);
    CHECK(s.physics.ballsKeepSpeed);
    CHECK(s.physics.friction > 0.0);
    CHECK(s.physics.restitution.tumblerTumbler < 1.0);
    CHECK(s.physics.wallDecay < 1.0);
}

TEST_CASE("physics.restitution and max_substeps are read and checked", "[sim][scene]") {
    Scene s;
    SceneError e;
    REQUIRE(parseScene(R"({"tumblers": [], "physics": {"max_substeps": 8,
        "restitution": {"ball_box": 0.9, "ball_lamp": 0.8, "ball_ball": 0.7, "ball_tumbler": 0.6,
                        "tumbler_tumbler": 0.25, "tumbler_floor": 0.1}}})", s, e));
    CHECK(s.physics.maxSubsteps == 8);
    CHECK(s.physics.restitution.ballBox == 0.9);
    CHECK(s.physics.restitution.ballLamp == 0.8);
    CHECK(s.physics.restitution.ballBall == 0.7);
    CHECK(s.physics.restitution.ballTumbler == 0.6);
    CHECK(s.physics.restitution.tumblerTumbler == 0.25);
    CHECK(s.physics.restitution.tumblerFloor == 0.1);
    CHECK(errorOf(R"({"tumblers": [], "physics": {"restitution": {"ball_box": 1.5}}})") ==
          "scenes/x.json: physics.restitution.ball_box: must be within [0.000000, 1.000000], got 1.5");
    CHECK(errorOf(R"({"tumblers": [], "physics": {"restitution": {"bounce": 1}}})") ==
          "scenes/x.json: physics.restitution.bounce: unknown key");
}

TEST_CASE("bad scene files give the JSON path and what is wrong", "[sim][scene]") {
    CHECK(errorOf("{\n  \"tumblers\": [ }") == "scenes/x.json: line 2, column 17: syntax error while parsing value - unexpected '}'; expected '[', '{', or a literal");
    CHECK(errorOf("{}") == "scenes/x.json: tumblers: missing (the list of tumblers, possibly empty)");
    CHECK(errorOf(R"({"tumblers": [{"position": [0.0, "a"]}]})") ==
          "scenes/x.json: tumblers[0].position[1]: expected a number, got a string");
    CHECK(errorOf(R"({"tumblers": [{"position": [0.95, 0.0]}]})") ==
          "scenes/x.json: tumblers[0].position: a tumbler of radius 0.200000 at this spot pokes out of the box");
    CHECK(errorOf(R"({"tumblers": [], "physics": {"dt": 5}})") ==
          "scenes/x.json: physics.dt: must be within [0.000010, 0.100000], got 5");
    CHECK(errorOf(R"({"tumblers": [], "physics": {"tumbler_mode": "fast"}})") ==
          "scenes/x.json: physics.tumbler_mode: expected one of \"course\", \"accurate\", got \"fast\"");
    CHECK(errorOf(R"({"tumblers": [], "marbles": [{"position": [0, 0.99, 0]}]})") ==
          "scenes/x.json: marbles[0].position: the ball (radius 0.05) does not fit inside the box [-1,1]^3");
    CHECK(errorOf(R"({"tumblers": [], "lamp": {"radius": 0.3, "colour": [1,1,1]}})") == "scenes/x.json: lamp.colour: unknown key");
    CHECK(errorOf(R"({"tumblers": [], "physics": {"dt": 0.01}, "marbles": [], "physics": {"dt": 0.02}})") ==
          "scenes/x.json: physics: duplicate key: only the last one would count");
    CHECK(errorOf(R"({"tumblers": [{"position": [0, 0], "position": [0.1, 0]}]})") ==
          "scenes/x.json: tumblers[0].position: duplicate key: only the last one would count");
    CHECK(errorOf(R"({"tumblers": [], "tumbler_shape": {"b": 0.1, "t": 0.2}})") ==
          "scenes/x.json: tumbler_shape.t: must be smaller than b (the upper sphere sits on the lower one)");
    CHECK(errorOf(R"({"tumblers": {}})") == "scenes/x.json: tumblers: expected an array, got an object");
    CHECK(errorOf(R"({"tumblers": [], "physics": {"substeps": 2.5}})") ==
          "scenes/x.json: physics.substeps: expected an integer, got 2.5");
}

TEST_CASE("more bad scene files: overlap, tilt, nesting, missing keys, files", "[sim][scene]") {
    // Two tumblers 0.3 apart: their lower spheres (radius 0.2) overlap.
    CHECK(errorOf(R"({"tumblers": [{"position": [0, 0]}, {"position": [0.3, 0]}]})") ==
          "scenes/x.json: tumblers[1].position: overlaps tumblers[0]");
    // Tilted towards the wall it pokes out with its upper sphere.
    CHECK(errorOf(R"({"tumblers": [{"position": [0.75, 0], "tilt": [0, -1.2]}]})") ==
          "scenes/x.json: tumblers[0].tilt: with this tilt the tumbler's upper sphere is outside the box");
    CHECK(errorOf(R"({"tumblers": [{"tilt": [0, 0]}]})") ==
          "scenes/x.json: tumblers[0].position: missing (a tumbler needs a position [x, z] on the floor)");
    CHECK(errorOf(R"({"tumblers": [], "box": {"floor_wood": {"dark": [0.1, 0.2, 1.5]}}})") ==
          "scenes/x.json: box.floor_wood.dark[2]: must be within [0.000000, 1.000000], got 1.5");
    CHECK(errorOf(R"({"tumblers": [], "fireballs": [{"velocity": [1, 2, 3]}]})") ==
          "scenes/x.json: fireballs[0].position: missing (a ball needs a position)");
    CHECK(errorOf(R"({"tumblers": [], "marbles": [{"position": [0, 0, 0], "radius": "big"}]})") ==
          "scenes/x.json: marbles[0].radius: expected a number, got a string");
    CHECK(errorOf("[1, 2]") == "scenes/x.json: the scene must be a JSON object, got an array");
    // Malformed JSON: the line (and column where the parser noticed) of a missing comma.
    CHECK(errorOf("{\n  \"tumblers\": [],\n  \"marbles\": [] \"fireballs\": []\n}").rfind("scenes/x.json: line 3, column 27: syntax error", 0) == 0);

    const SceneResult missing = loadSceneFile("/nonexistent/scene.json");
    CHECK_FALSE(missing);
    CHECK(missing.error.toString("/nonexistent/scene.json") == "/nonexistent/scene.json: cannot read the scene file");
    std::string error;
    Scene s;
    CHECK_FALSE(loadScene("/nonexistent/scene.json", s, error));
    CHECK(error == "/nonexistent/scene.json: cannot read the scene file");
}

TEST_CASE("the shipped scene carries the renderer's values", "[sim][scene]") {
    const SceneResult r = loadSceneFile(std::string(KILN_SOURCE_DIR) + "/scenes/cornell.json");
    REQUIRE(r);
    const Scene& s = r.scene;
    CHECK(s.box.left.r > s.box.left.b);    // orange
    CHECK(s.box.right.b > s.box.right.r);  // sky blue
    CHECK(s.box.floorWood.ringFrequency > 0);
    CHECK(s.lamp.center == glm::dvec3(0, 1.1, 0));
    CHECK(s.lamp.center.y - s.lamp.radius == Approx(0.75));  // the dome's lowest point
    CHECK(s.tumblerShape.b == 0.2);
    CHECK(s.tumblerShape.t == 0.1);
    CHECK(s.tumblerShape.alpha == Approx(M_PI / 9).epsilon(1e-12));
    CHECK(s.physics.dt == Approx(1.0 / 240));
    CHECK(s.marbles.size() >= 2);
    // Parsing text gives the same as the file.
    const SceneResult again = parseSceneText(R"({"tumblers": [{"position": [0.1, -0.2], "color": [1, 0, 0]}]})");
    REQUIRE(again);
    CHECK(again.scene.tumblers[0].position == glm::dvec2(0.1, -0.2));
}

// ---- Hostile scene files: every one is a named error, none throws, hangs
// or overflows the stack.

TEST_CASE("a number beyond double range is a named error at its JSON path", "[sim][scene][bad-input]") {
    CHECK(errorOf(R"({"tumblers": [], "physics": {"dt": 1e999}})") ==
          "scenes/x.json: physics.dt: line 1, column 36: number overflow parsing '1e999' (beyond the range of a double)");
    CHECK(errorOf(R"({"tumblers": [], "marbles": [{"position": [0, -1e999, 0]}]})")
              .rfind("scenes/x.json: marbles[0].position[1]: line 1, column 47: number overflow", 0) == 0);
    // What the fuzzer found first: 8 bytes, no closing bracket.
    CHECK(errorOf("[22E444").find("number overflow") != std::string::npos);
}

TEST_CASE("deep nesting is refused before parsing, quickly and in a short message", "[sim][scene][bad-input]") {
    const std::string deep = R"({"tumblers": [], "note": )" + std::string(100000, '[') + std::string(100000, ']') + "}";
    const std::string e = errorOf(deep);
    CHECK(e == "scenes/x.json: line 1, column 57: nested deeper than 32 levels");
    // 32 levels are fine (the note may be anything).
    const std::string ok = R"({"tumblers": [], "note": )" + std::string(31, '[') + std::string(31, ']') + "}";
    Scene s;
    SceneError err;
    CHECK(parseScene(ok, s, err));
    // Brackets inside strings do not count.
    CHECK(parseScene(R"({"tumblers": [], "note": ")" + std::string(1000, '[') + "\"}", s, err));
}

TEST_CASE("error messages quote values elided, never a whole huge value", "[sim][scene][bad-input]") {
    std::string big = "[";
    for (int i = 0; i < 100000; ++i) big += (i ? ",1" : "1");
    big += "]";
    const std::string e = errorOf(R"({"tumblers": [], "marbles": [{"position": [0, 0, 0], "radius": )" + big + "}]}");
    CHECK(e.rfind("scenes/x.json: marbles[0].radius: expected a number, got an array", 0) == 0);
    const std::string e2 = errorOf(R"({"tumblers": [], "physics": {"tumbler_mode": ")" + std::string(100000, 'x') + "\"}}");
    CHECK(e2.size() < 300);
    CHECK(e2.find("…(+") != std::string::npos);
    const std::string e3 = errorOf(R"({"tumblers": [], ")" + std::string(100000, 'k') + "\": 1}");
    CHECK(e3.size() < 300);
}

TEST_CASE("a directory passed as the scene file is a clear error", "[sim][scene][bad-input]") {
    const SceneResult r = loadSceneFile(std::string(KILN_SOURCE_DIR) + "/scenes");
    REQUIRE_FALSE(r);
    CHECK(r.error.message == "is a directory, not a scene file");
}

namespace {
std::string ballList(size_t n, const char* radius, double spacing) {
    std::string s = "[";
    const int side = int(std::ceil(std::cbrt(double(n))));
    for (size_t i = 0; i < n; ++i) {
        const double x = -0.5 + spacing * double(i % side), y = -0.5 + spacing * double((i / side) % side),
                     z = -0.5 + spacing * double(i / (side * side));
        s += (i ? ", " : "") + std::string("{\"position\": [") + std::to_string(x) + ", " + std::to_string(y) + ", " +
             std::to_string(z) + "], \"radius\": " + radius + "}";
    }
    return s + "]";
}
}  // namespace

TEST_CASE("counts beyond the limits are named errors with the limit", "[sim][scene][bad-input]") {
    CHECK(errorOf(R"({"tumblers": [], "marbles": )" + ballList(kMaxMarbles + 1, "0.005", 0.011) + "}") ==
          "scenes/x.json: marbles: 1025 marbles, more than the limit of 1024");
    CHECK(errorOf(R"({"tumblers": [], "fireballs": )" + ballList(kMaxFireballs + 1, "0.005", 0.011) + "}") ==
          "scenes/x.json: fireballs: 65 fireballs, more than the limit of 64");
    std::string tumblers = "[";
    for (size_t i = 0; i <= kMaxTumblers; ++i) tumblers += (i ? ",{}" : "{}");
    CHECK(errorOf(R"({"tumblers": )" + tumblers + "]}") == "scenes/x.json: tumblers: 65 tumblers, more than the limit of 64");
}

namespace {
struct StepRun {
    double slowestSeconds = 0.0;  // printed, never asserted (shared, noisy machines)
    int mostSubsteps = 0;
};
// Steps the world, noting the slowest step and the most sub-steps one used; every ball
// stays finite and inside the box.
StepRun stepAndWatch(const Scene& scene, int steps) {
    World w(scene);
    StepRun run;
    for (int k = 0; k < steps; ++k) {
        run.mostSubsteps = std::max(run.mostSubsteps, w.substepsFor(scene.physics.dt));
        const auto t0 = std::chrono::steady_clock::now();
        w.step();
        run.slowestSeconds = std::max(run.slowestSeconds, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    }
    for (const Ball& b : w.balls()) {
        REQUIRE(std::isfinite(b.position.x + b.position.y + b.position.z));
        for (int a = 0; a < 3; ++a) REQUIRE(std::abs(b.position[a]) <= 1.0 - b.radius + 1e-9);
    }
    return run;
}
}  // namespace

TEST_CASE("a scene at the count limits, every ball in one grid cell, steps in bounded time", "[sim][scene][bad-input]") {
    // One big fireball makes the broad phase's cells 2/3 wide; 1024 small marbles packed
    // into one cell are then all pairs of each other (the worst case the limits allow).
    const std::string packed = R"({"tumblers": [], "fireballs": [{"position": [0.6, 0.6, 0.6], "radius": 0.3}],
        "marbles": )" + ballList(kMaxMarbles, "0.005", 0.011) + "}";
    const SceneResult a = parseSceneText(packed);
    REQUIRE(a);
    const StepRun packedStep = stepAndWatch(a.scene, 20);
    // Every ball at the same point: all pairs overlap, the pile explodes.
    std::string same = R"({"tumblers": [], "marbles": [)";
    for (size_t i = 0; i < kMaxMarbles; ++i) same += (i ? "," : "") + std::string(R"({"position": [0, 0, 0]})");
    same += R"(], "fireballs": [)";
    for (size_t i = 0; i < kMaxFireballs; ++i) same += (i ? "," : "") + std::string(R"({"position": [0, 0, 0]})");
    same += "]}";
    const SceneResult b = parseSceneText(same);
    REQUIRE(b);
    const StepRun sameStep = stepAndWatch(b.scene, 20);
    // The same at Δt 0.1 and 100 m/s: adaptive sub-stepping wants its 4096 sub-steps of
    // all pairs; the step's work budget gives it far fewer.
    std::string fast = R"({"tumblers": [], "physics": {"dt": 0.1, "max_substeps": 4096}, "marbles": [)";
    for (size_t i = 0; i < kMaxMarbles; ++i)
        fast += (i ? "," : "") + std::string(R"({"position": [0, 0, 0], "velocity": [100, 100, 100], "radius": 0.005})");
    fast += R"(], "fireballs": [)";
    for (size_t i = 0; i < kMaxFireballs; ++i) fast += (i ? "," : "") + std::string(R"({"position": [0, 0, 0], "radius": 0.3})");
    fast += "]}";
    const SceneResult c = parseSceneText(fast);
    REQUIRE(c);
    const StepRun fastStep = stepAndWatch(c.scene, 10);
    std::printf("step at the count limits: packed in one cell %.1f ms, all at one point %.1f ms, "
                "all at one point at dt 0.1 and 100 m/s %.1f ms (slowest step; %d, %d, %d sub-steps at most)\n",
                packedStep.slowestSeconds * 1e3, sameStep.slowestSeconds * 1e3, fastStep.slowestSeconds * 1e3,
                packedStep.mostSubsteps, sameStep.mostSubsteps, fastStep.mostSubsteps);
    // Bounded work, not time (no timing assertions in the suite): with every ball a pair
    // of every other, sub-steps × pairs stays within the step's work budget (2^22, see
    // World::substepsFor), though the fast scene's speeds ask for 4096 sub-steps.
    const double balls = double(kMaxMarbles + kMaxFireballs), allPairs = balls * (balls - 1.0) / 2.0;
    CHECK(sameStep.mostSubsteps * allPairs <= double(1 << 22));
    CHECK(fastStep.mostSubsteps * allPairs <= double(1 << 22));
    CHECK(fastStep.mostSubsteps >= 1);
    const double packedBalls = double(kMaxMarbles + 1);  // and the one big fireball
    CHECK(packedStep.mostSubsteps * packedBalls * (packedBalls - 1.0) / 2.0 <= double(1 << 22));
}

TEST_CASE("models are read and checked, and a scene without walls holds no bodies", "[sim][scene]") {
    Scene s;
    SceneError e;
    REQUIRE(parseScene(R"({"tumblers": [], "models": [{"file": "a.glb", "position": [0, -1, 0], "scale": 0.5,
                            "rotation_deg": [0, 90, 0], "fit": true}]})", s, e));
    REQUIRE(s.models.size() == 1);
    CHECK(s.models[0].file == "a.glb");
    CHECK(s.models[0].scale == 0.5);
    CHECK(s.models[0].rotationDeg.y == 90.0);
    CHECK(s.models[0].fit);
    CHECK(errorOf(R"({"tumblers": [], "models": [{"position": [0, 0, 0]}]})").find("models[0].file: expected") !=
          std::string::npos);
    CHECK(errorOf(R"({"tumblers": [], "models": [{"file": "a.glb", "scale": 0}]})").find("models[0].scale") !=
          std::string::npos);
    CHECK(errorOf(R"({"tumblers": [], "models": [{"file": "a.glb", "colour": 1}]})")
              .find("models[0].colour: unknown key") != std::string::npos);
    REQUIRE(parseScene(R"({"box": {"walls": false}, "tumblers": []})", s, e));
    CHECK_FALSE(s.box.walls);
    CHECK(errorOf(R"({"box": {"walls": false}, "tumblers": [{"position": [0, 0]}]})")
              .find("box.walls: false, but the scene has 1 tumblers") != std::string::npos);
}
