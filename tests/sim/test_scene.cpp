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
