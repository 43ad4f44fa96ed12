// Bad scene files: each error names the JSON path and what is wrong.
#include <catch2/catch.hpp>

#include "kiln/sim/scene.hpp"

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
    // It states the restitution of every contact kind: all elastic.
    CHECK(s.physics.restitution.ballBox == 1.0);
    CHECK(s.physics.restitution.tumblerTumbler == 1.0);
    CHECK(s.physics.restitution.tumblerFloor == 1.0);
    CHECK(s.physics.wallDecay == 1.0);
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
          "scenes/x.json: physics.tumbler_mode: expected one of \"seed\", \"accurate\", got \"fast\"");
    CHECK(errorOf(R"({"tumblers": [], "marbles": [{"position": [0, 0.99, 0]}]})") ==
          "scenes/x.json: marbles[0].position: the ball (radius 0.05) does not fit inside the box [-1,1]^3");
    CHECK(errorOf(R"({"tumblers": [], "lamp": {"radius": 0.3, "colour": [1,1,1]}})") == "scenes/x.json: lamp.colour: unknown key");
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
