// kiln/sim/scene.hpp — the scene file (scenes/cornell.json) as plain data, read by the
// simulation, the renderer and the reference alike.
//
//   {
//     "box":   { "left": [r,g,b], "right": [r,g,b], "other": [r,g,b] },
//     "lamp":  { "center": [0, 1.1, 0], "radius": 0.35, "color": [r,g,b], "intensity": 4 },
//     "physics": { "dt": 0.004166, "substeps": 4, "gravity": 9.81, "friction": 0.005,
//                  "wall_decay": 0.5, "tumbler_mode": "seed" | "accurate",
//                  "tumbler_contact": "four_spheres" | "exact", "ballast_h": 0.05, "seed": 1 },
//     "tumbler_shape": { "b": 0.2, "t": 0.1, "alpha_deg": 20, "mass": 1 },
//     "tumblers":  [ { "position": [x, z], "tilt": [about_x, about_z], "color": [r,g,b] } ],
//     "marbles":   [ { "position": [x,y,z], "velocity": [x,y,z], "radius": 0.05, "color": [r,g,b] } ],
//     "fireballs": [ { "position": [x,y,z], "velocity": [x,y,z], "radius": 0.06, "color": [r,g,b] } ]
//   }
//
// Every key is optional except "tumblers"; missing ones take the defaults below. Unknown
// keys are errors (a typo would otherwise be silently ignored), "note" excepted.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>

namespace kiln::sim {

struct SceneError {
    std::string path;     // JSON path, e.g. "tumblers[2].position"; empty for syntax errors
    std::string message;  // what is wrong (for syntax errors: "line L, column C: ...")
    std::string toString(const std::string& file) const;
};

enum class TumblerMode : uint8_t { Seed, Accurate };
enum class TumblerContact : uint8_t { FourSpheres, Exact };

struct Scene {
    struct Box {
        glm::dvec3 left{0.95, 0.45, 0.1}, right{0.35, 0.65, 0.95}, other{0.85, 0.82, 0.78};
    } box;
    struct Lamp {
        glm::dvec3 center{0.0, 1.1, 0.0};
        double radius = 0.35;
        glm::dvec3 color{1.0, 0.95, 0.85};
        double intensity = 4.0;
    } lamp;
    struct Physics {
        double dt = 1.0 / 240.0;
        int substeps = 4;
        double gravity = 9.81;
        double friction = 0.005;    // μ of the rocking/rolling damping (decel. μg/b rad/s²)
        double wallDecay = 0.5;     // tumbler velocity kept after hitting a wall
        TumblerMode tumblerMode = TumblerMode::Accurate;
        TumblerContact tumblerContact = TumblerContact::Exact;
        double ballastH = 0.05;     // accurate mode: centre of mass this far below O (negative:
                                    // above; a uniform tumbler's is −0.0521, and it cannot stand)
        uint64_t seed = 1;
    } physics;
    struct TumblerShape {
        double b = 0.2, t = 0.1, alpha = 0.3490658503988659, mass = 1.0;
    } tumblerShape;
    struct TumblerSpec {
        glm::dvec2 position{0.0};  // x, z on the floor
        glm::dvec2 tilt{0.0};      // radians about x and z
        glm::dvec3 color{0.9, 0.2, 0.2};
    };
    struct BallSpec {
        glm::dvec3 position{0.0}, velocity{0.0};
        double radius = 0.05;
        glm::dvec3 color{0.8};
    };
    std::vector<TumblerSpec> tumblers;
    std::vector<BallSpec> marbles, fireballs;
};

// Parses and validates; on failure returns false and fills `error`.
bool parseScene(const std::string& text, Scene& out, SceneError& error);
bool loadScene(const std::string& path, Scene& out, std::string& error);

}  // namespace kiln::sim
