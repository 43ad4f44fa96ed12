// kiln/sim/scene.hpp — the scene file (scenes/cornell.json) as plain data. One parser
// for everyone: the simulation, the renderer and the path-traced reference all read the
// scene through this header (see also scenes/README.md).
//
// Format (all lengths in metres inside the box [-1,1]³, the floor is y = −1; colours
// linear RGB in [0,1]; angles in radians unless the key says _deg):
//
//   {
//     "box": {                                   // the Cornell box's look
//       "left": [r,g,b],  "right": [r,g,b],      // x = −1 wall (orange), x = +1 (sky blue)
//       "other": [r,g,b],                        // back wall, ceiling (and floor tint)
//       "floor_wood": { "light": [r,g,b], "dark": [r,g,b], "ring_frequency": 14 },
//       "emission": [r,g,b],                     // radiance every wall emits (default 0)
//       "closed": false,                         // a front wall at z = +1 (colour "other")
//       "walls": true,                           // false: no walls and no lamp, and then no
//                                                //   tumblers, marbles or fireballs
//       "lamp": true                             // the lamp (default: as "walls"); with no
//     },                                         //   walls it hangs alone, clipped at y = 1
//     "lamp": { "center": [0, 1.1, 0], "radius": 0.35,   // sphere clipped by the ceiling: the
//               "color": [r,g,b], "intensity": 20 },     // dome below y = 1 emits the
//                                                        // radiance color × intensity
//     "physics": {
//       "dt": 0.0041667,            // one frame (s), (0, 0.1]
//       "substeps": 4,              // sub-steps per frame, 1..64
//       "max_substeps": 256,        // adaptive ceiling for fast bodies, ≥ 1 (≤ substeps: off,
//                                   //   allowed only with dt/substeps ≤ 1/240 s)
//       "gravity": 9.81,            // m/s², [0, 100]
//       "friction": 0.005,          // μ of the rocking damping (docs/physics.md §3), [0, 10]
//       "wall_decay": 0.5,          // tumbler velocity kept after hitting a wall, [0, 1]
//       "balls_keep_speed": false,  // a ball leaves a tumbler at the speed it came (the
//                                   //   tumbler still takes the impulse): the balls keep
//                                   //   their energy while friction damps the tumblers
//       "tumbler_mode": "course" | "accurate",         // restoring impulse | weighted base
//       "tumbler_contact": "four_spheres" | "exact", // tumbler-vs-tumbler method
//       "ballast_h": 0.05,          // accurate mode: centre of mass this far below O
//       "seed": 1,                  // random generator seed (integer ≥ 0)
//       "restitution": {            // normal restitution e ∈ [0, 1] of each contact kind,
//         "ball_box": 1,            //   honoured exactly: v_n after = −e · v_n before
//         "ball_lamp": 1,           //   (relative normal velocity at the contact point;
//         "ball_ball": 1,           //   tumblers answer with their rolling-constrained
//         "ball_tumbler": 1,        //   effective mass). Balls: 1 (docs/physics.md §4, no loss).
//         "tumbler_tumbler": 0.5,   //   Tumbler vs wall: "wall_decay" above.
//         "tumbler_floor": 0 }      //   A toppled tumbler's side/upper sphere landing.
//     },
//     "tumbler_shape": { "b": 0.2, "t": 0.1, "alpha_deg": 20, "mass": 1 },
//     "tumblers": [                               // required (may be empty)
//       { "position": [x, z], "tilt": [about_x, about_z], "color": [r,g,b] } ],
//     "marbles":   [ { "position": [x,y,z], "velocity": [x,y,z], "radius": 0.05, "color": [r,g,b] } ],
//     "fireballs": [ { "position": [x,y,z], "velocity": [x,y,z], "radius": 0.06, "color": [r,g,b] } ],
//     "models": [                                 // glTF 2.0 files drawn in the box (the bodies
//       { "file": "model.glb",                    //   pass through them); the path is relative
//         "position": [x,y,z], "scale": 1,        //   to the scene file. Placed by translate ×
//         "rotation_deg": [x,y,z],                //   rotate (about x, then y, then z) × scale,
//         "fit": false } ]                        //   or, with "fit", scaled and moved so its
//   }                                             //   bounds stand on the floor within [-0.8,0.8]
//
// Every key is optional except "tumblers" and each entry's "position"; missing ones take
// the defaults below. Unknown keys are errors (a typo would otherwise be silently
// ignored); "note" and "$schema" are allowed anywhere. Checked beyond types and ranges:
// t < b, every tumbler (both spheres, with its tilt) inside the box, tumblers not
// overlapping each other, every ball inside the box.
//
// Limits (each a named error with the limit in it): at most kMaxTumblers tumblers,
// kMaxMarbles marbles, kMaxFireballs fireballs; nesting at most kMaxSceneNesting deep;
// a file of at most kMaxSceneFileBytes. A number beyond double range (1e999) is an error
// at its JSON path. Messages quote values elided to a few dozen characters.
//
// Errors carry the JSON path (`tumblers[2].position`, `physics.dt`, `marbles[0].radius`)
// and what is wrong; a syntax error carries "line L, column C: ..." and an empty path.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>

namespace kiln::sim {

// Bounds on what a scene may ask for: every step stays bounded (the ball broad phase is
// at worst quadratic in the balls sharing a grid cell, ~ (kMaxMarbles + kMaxFireballs)²).
inline constexpr size_t kMaxTumblers = 64;
inline constexpr size_t kMaxMarbles = 1024;
inline constexpr size_t kMaxFireballs = 64;
inline constexpr size_t kMaxModels = 64;
inline constexpr int kMaxSceneNesting = 32;  // as the pipeline loader
inline constexpr size_t kMaxSceneFileBytes = size_t(16) << 20;
// The longest fixed sub-step (adaptive sub-steps off) a scene may ask for; longer ones
// let a tumbler spun by ball hits gain energy without bound (tests/sim/test_conservation.cpp).
inline constexpr double kMaxFixedSubstep = 1.0 / 240.0;

struct SceneError {
    std::string path;     // JSON path, e.g. "tumblers[2].position"; empty for syntax errors
    std::string message;  // what is wrong (for syntax errors: "line L, column C: ...")
    // "FILE: PATH: MESSAGE" (or "FILE: MESSAGE" without a path): one line for a terminal.
    std::string toString(const std::string& file) const;
};

enum class TumblerMode : uint8_t { Course, Accurate };
enum class TumblerContact : uint8_t { FourSpheres, Exact };

struct Scene {
    struct Box {
        glm::dvec3 left{0.95, 0.45, 0.1}, right{0.35, 0.65, 0.95}, other{0.85, 0.82, 0.78};
        struct FloorWood {
            glm::dvec3 light{0.72, 0.52, 0.32}, dark{0.45, 0.28, 0.15};
            double ringFrequency = 14.0;  // growth rings per metre of radius
        } floorWood;
        glm::dvec3 emission{0.0};  // radiance of every wall (a white-furnace test sets it)
        bool closed = false;       // a sixth wall closes the front (camera inside)
        bool walls = true;         // false: no walls (a model lit by its own lights); such a
                                   //   scene holds no bodies
        bool lamp = true;          // the lamp; the file's default is `walls` (a model that is
                                   //   its own room can keep the box's lamp)
    } box;
    struct Lamp {
        glm::dvec3 center{0.0, 1.1, 0.0};
        double radius = 0.35;
        glm::dvec3 color{1.0, 0.95, 0.85};
        double intensity = 20.0;
    } lamp;
    struct Physics {
        double dt = 1.0 / 240.0;
        int substeps = 4;
        int maxSubsteps = 256;      // adaptive sub-stepping's ceiling (≤ substeps: fixed count)
        double gravity = 9.81;
        double friction = 0.005;    // μ of the rocking/rolling damping (decel. μg/b rad/s²)
        double wallDecay = 0.5;     // tumbler-wall restitution: normal velocity kept after a hit
        bool ballsKeepSpeed = false;  // a ball's speed relative to the box is kept through a tumbler hit
        TumblerMode tumblerMode = TumblerMode::Accurate;
        TumblerContact tumblerContact = TumblerContact::Exact;
        double ballastH = 0.05;     // accurate mode: centre of mass this far below O (negative:
                                    // above; a uniform tumbler's is −0.0521, and it cannot stand)
        uint64_t seed = 1;
        // Normal restitution per contact kind (the tumbler-wall one is wallDecay).
        struct Restitution {
            double ballBox = 1.0, ballLamp = 1.0, ballBall = 1.0, ballTumbler = 1.0;
            double tumblerTumbler = 0.5, tumblerFloor = 0.0;
        } restitution;
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
    struct ModelSpec {
        std::string file;             // as the scene file gives it
        glm::dvec3 position{0.0};
        double scale = 1.0;
        glm::dvec3 rotationDeg{0.0};  // about x, then y, then z
        bool fit = false;             // scaled and moved to stand inside the box (then
                                      //   scaled and turned about its base's middle, and
                                      //   moved by position)
    };
    std::vector<ModelSpec> models;
};

// Either a scene or an error (never both).
struct SceneResult {
    Scene scene;       // valid when ok()
    SceneError error;  // set when !ok()
    bool valid = false;
    bool ok() const { return valid; }
    explicit operator bool() const { return valid; }
};

// Parses and validates scene text (tests, live editing).
SceneResult parseSceneText(const std::string& text);
// Reads and parses a file; an unreadable file gives path "" and "cannot read ...".
SceneResult loadSceneFile(const std::string& path);

// The same, bool-returning (kept for the host): on failure returns false and fills
// `error` (for loadScene: one line "FILE: PATH: MESSAGE"); `out` is left untouched.
bool parseScene(const std::string& text, Scene& out, SceneError& error);
bool loadScene(const std::string& path, Scene& out, std::string& error);

}  // namespace kiln::sim
