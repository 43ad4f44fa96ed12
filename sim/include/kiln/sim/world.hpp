// kiln/sim/world.hpp — the simulation of Kiln's scene: tumblers rolling on the floor
// of the Cornell box [-1,1]³, marbles and fireballs bouncing without loss, fire and
// particles, and mouse picking. Plain data in arrays and a fixed-Δt step; no OpenGL,
// no hidden globals: same scene, seed and inputs ⇒ bit-identical state (stateHash).
//
// Use:
//   kiln::sim::SceneResult r = kiln::sim::loadSceneFile("scenes/cornell.json");
//   if (!r) { std::cerr << r.error.toString("scenes/cornell.json") << "\n"; return 1; }
//   kiln::sim::World world(r.scene);
//   each frame (unless paused): world.step();          // dt = scene.physics.dt
//   if (world.bodiesVersion() != seen) upload tumblers()/balls() (the host writes its
//   own instance records from them); likewise particlesVersion() for particles().
//
// Model (docs/physics.md): a tumbler's lower-sphere centre O stays at y = −1 + b and it rolls
// without slipping; "course" mode puts the centre of mass at O and adds the course design's
// restoring impulse, "accurate" mode puts it ballast_h below O so gravity rights it.
// Balls (marbles with gravity, fireballs without) reflect without loss off the box,
// the lamp dome, tumblers (momentum-conserving impulse) and each other (elastic).
// Units: metres, seconds, kilograms (a tumbler's mass is scene.tumblerShape.mass).
//
// Limits: tumblers never leave the floor (no jumping); ball-ball and ball-tumbler
// contacts are resolved pairwise once per sub-step (no simultaneous solve), so dense
// piles jitter; particles are capped at World::kMaxParticles (new ones are dropped).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "kiln/sim/scene.hpp"
#include "kiln/sim/shape.hpp"

namespace kiln::sim {

// PCG32 (O'Neill): small, fast and identical on every standard library, unlike the
// std:: distributions.
class Rng {
public:
    explicit Rng(uint64_t seed = 1) { reseed(seed); }
    void reseed(uint64_t seed);
    uint32_t next();
    double uniform() { return next() * (1.0 / 4294967296.0); }               // [0, 1)
    double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }
    Vec3 inUnitBall();
    Vec3 onUnitSphere();
    // The generator's full state (for World::stateHash).
    uint64_t state() const { return state_; }
    uint64_t stream() const { return inc_; }

private:
    uint64_t state_ = 0, inc_ = 0;
};

struct Tumbler {
    Vec3 position{0.0};     // lower-sphere centre O (the local origin)
    Quat orientation{1, 0, 0, 0};
    Vec3 velocity{0.0};     // of O
    Vec3 angularVelocity{0.0};
    Vec3 color{1.0};
    bool asleep = false;
    double restTime = 0.0;  // seconds below the sleep thresholds

    Mat3 rotation() const { return glm::mat3_cast(orientation); }
    Vec3 axis() const { return rotation() * Vec3(0, 1, 0); }
    Vec3 upperCentre(const RoundCone& s) const { return position + rotation() * Vec3(0, s.upperCentre(), 0); }
    // Column-major 4×4 model matrix (float, ready for a GPU instance buffer).
    void modelMatrix(float out[16]) const;
};

enum class BallKind : uint8_t { Marble, Fireball, Burning };

// Seconds a burning marble glows before it crumbles to ash (removed, ash particles).
inline constexpr double kBurnDuration = 1.2;

struct Ball {
    Vec3 position{0.0}, velocity{0.0}, angularVelocity{0.0};
    double radius = 0.05;
    BallKind kind = BallKind::Marble;
    Vec3 color{0.8};
    double burnTime = 0.0;  // seconds burning (BallKind::Burning)
    double fireOwed = 0.0;  // fractional fire particles owed (fireballs, burning marbles)
    double mass() const { return radius * radius * radius * 8000.0; }  // ∝ volume, glass-ish scale
    // What the renderer draws: the diffuse colour (a burning marble darkens towards ash)
    // and the emission, colour × strength (fireballs and burning marbles glow).
    Vec3 albedo() const;
    Vec3 emissiveColor() const;
    double emissiveStrength() const;
};

enum class ParticleKind : uint8_t { Fire, Spark, Ash };

struct Particle {
    Vec3 position{0.0}, velocity{0.0};
    double life = 0.0, maxLife = 1.0;  // seconds left / at birth
    double size = 0.01;                // radius at birth
    ParticleKind kind = ParticleKind::Fire;
    // Current radius and emitted colour (docs/physics.md §6: they follow the remaining life).
    double radius() const;
    Vec3 emission() const;
};

// Solves K·j = Δv for a symmetric positive semi-definite 3×3 K (an effective-mass
// matrix, K = (1/m)𝟙 − [r]×I⁻¹[r]×). When K is singular or nearly so (relative to its
// scale) it returns the minimum-norm least-squares solution (pseudo-inverse, eigenvalues
// below 1e-9·λ_max dropped): finite for every finite input; K = 0 gives j = 0.
Vec3 solveImpulse(const Mat3& K, const Vec3& dv);

struct RayHit {
    int tumbler = -1;
    double distance = 0.0;
    Vec3 point{0.0};
};

enum class DragMode : uint8_t { Translate, Rotate };

class World {
public:
    World() = default;
    explicit World(const Scene& scene) { reset(scene); }

    // Starts over from `scene` (seed included).
    void reset(const Scene& scene);
    void reset() { reset(scene_); }
    // One fixed frame: `scene.physics.substeps` sub-steps of dt / substeps, or more
    // (up to scene.physics.maxSubsteps) when a body is fast enough to outrun its contacts.
    void step();
    // The sub-step count step() would use for a frame of `frame` seconds now.
    int substepsFor(double frame) const;
    // The count a frame starts from: the scene's substeps, raised (when sub-steps adapt)
    // until none is longer than kMaxFixedSubstep.
    static int fewestSubsteps(const Scene::Physics&);

    const Scene& scene() const { return scene_; }
    const RoundCone& shape() const { return shape_; }
    const MassProperties& massProperties() const { return mass_; }
    double time() const { return time_; }
    uint64_t stepCount() const { return steps_; }

    std::vector<Tumbler>& tumblers() { return tumblers_; }
    const std::vector<Tumbler>& tumblers() const { return tumblers_; }
    std::vector<Ball>& balls() { return balls_; }
    const std::vector<Ball>& balls() const { return balls_; }
    const std::vector<Particle>& particles() const { return particles_; }

    // The particle pool's size: particles_ never grows beyond it (no reallocation).
    static constexpr size_t kMaxParticles = 4096;

    // Bumped on each step in which a body moved / the particle set changed; a world
    // whose bodies all sleep (or that is not stepped) keeps them.
    uint64_t bodiesVersion() const { return bodiesVersion_; }
    uint64_t particlesVersion() const { return particlesVersion_; }

    void spawnMarble(const Vec3& position, const Vec3& velocity, double radius = 0.05);
    void spawnFireball(const Vec3& position, const Vec3& velocity, double radius = 0.06);
    // Spawns at a random spot (x, z ∈ [−0.7, 0.7], y ∈ [0, 0.6]) with a random velocity
    // of 1–3 m/s, drawn from the world's seeded generator (keyboard shortcuts); nothing
    // once there are kMaxMarbles + kMaxFireballs balls.
    void spawnRandom(BallKind kind);

    // Signed distance from a world point to tumbler i, and the outward normal there.
    double tumblerSdf(int i, const Vec3& p) const;
    Vec3 tumblerNormal(int i, const Vec3& p) const;

    // Sphere-traces the ray against every tumbler; the nearest hit wins.
    std::optional<RayHit> raycastTumblers(const Vec3& origin, const Vec3& direction) const;
    // A hit below the centre of mass translates, above rotates (docs/physics.md §4, picking).
    DragMode beginDrag(const RayHit& hit);
    // Translate: the tumbler follows the ray's intersection with the plane y = s_y.
    void dragTo(const Vec3& rayOrigin, const Vec3& rayDirection);
    // Rotate: tilt by (about world x, about world z) radians and roll the matching distance.
    void dragRotate(double aboutX, double aboutZ);
    void endDrag();
    int dragged() const { return drag_.tumbler; }

    // Resolves ball `ball` against tumbler `tumbler` if they overlap: pushes the ball
    // out and exchanges an elastic impulse (no floor involved). True on contact.
    bool resolveBallTumblerContact(int ball, int tumbler);
    // Resolves two balls if they overlap: separation weighted by mass, elastic impulse
    // (momentum and kinetic energy kept); a fireball touching a marble ignites it.
    bool resolveBallBallContact(int a, int b);
    // Resolves tumblers a and b with the scene's method; returns the separation it saw
    // (negative: overlap) or +inf when they are too far apart to test.
    double resolveTumblerPair(int a, int b);
    // Applies impulse j at world point p to tumbler i as a free body (no floor; the
    // course design's model). Contacts use applyRollingImpulse.
    void applyImpulse(int i, const Vec3& p, const Vec3& j);
    // Applies impulse j at world point p to tumbler i while it rolls on the floor: the
    // floor answers with whatever impulse at the contact point keeps it rolling without
    // slipping, so Δω = A⁻¹·((p − P) × j) with A = rollingInertia(i), and the velocity
    // stays consistent with the constraint (nothing is discarded at the next sub-step).
    void applyRollingImpulse(int i, const Vec3& p, const Vec3& j);
    // The floor contact P = O − b·ŷ (the lowest point of the lower sphere).
    Vec3 floorContact(int i) const;
    // Inertia about the floor contact, world frame: A = I_G + m(|r|²𝟙 − r·rᵀ), r = G − P.
    // The rolling body's kinetic energy is ½ωᵀAω and its angular momentum about P is Aω.
    Mat3 rollingInertia(int i) const;
    // Inverse effective mass of tumbler i at world point p along unit n given that it
    // rolls: n·Δv_p per unit impulse along n, = (ρ×n)ᵀA⁻¹(ρ×n), ρ = p − P.
    double rollingInverseMass(int i, const Vec3& p, const Vec3& n) const;
    // Mechanical energy of tumbler i (rolling kinetic ½ωᵀAω + m·g·G_y, floor at y = −1
    // is not subtracted) and Jellett's quantity L_G·(G − P) = L_P·(G − P), conserved by
    // frictionless rolling of a body of revolution on a sphere base (docs/physics.md §3).
    double tumblerEnergy(int i) const;
    double tumblerJellett(int i) const;
    // Σ tumblerEnergy + Σ ball mass × ballEnergy (the balls' modified energy E′).
    double totalEnergy() const;
    // Energy (mass × E′) that burnt marbles took with them when they crumbled to ash:
    // totalEnergy() + removedBallEnergy() is what an energy-conserving run keeps.
    double removedBallEnergy() const { return removedBallEnergy_; }
    // Velocity of the material point of tumbler i at world point p.
    Vec3 pointVelocity(int i, const Vec3& p) const;
    // World-space inverse inertia of tumbler i about its centre of mass.
    Mat3 inverseInertiaWorld(int i) const;
    Vec3 centreOfMass(int i) const;
    double tumblerMass() const { return scene_.tumblerShape.mass; }

    // FNV-1a over all of the state: every field of every tumbler, ball and particle,
    // the generator, time, step count and the drag in progress.
    uint64_t stateHash() const;

    // A ball's modified mechanical energy per unit mass in free flight,
    // E′ = ½|v|² + g·y − ½·g·Δt·v_y with Δt the sub-step in effect (the scene's dt /
    // substeps unless adaptive sub-steps are running; gravity-free balls: ½|v|²).
    // Semi-implicit Euler keeps it exactly between bounces, and the time-symmetric
    // wall bounce keeps it exactly across them (docs/physics.md §4).
    double ballEnergy(int ball) const;

    // Diagnostics for tests and `kiln-sim run`.
    double maxQuaternionError() const;  // max | |q| − 1 |
    bool allFinite() const;
    double maxContainmentViolation() const;  // how far any sphere pokes out of the box
    // The most negative exact separation of any two tumblers (0 when none overlap).
    double deepestTumblerOverlap() const;

private:
    void substep(double dt);
    void stepTumbler(int i, double dt);
    void stepTumblerCourse(int i, double dt);
    void stepTumblerRolling(int i, double dt);
    void applyFriction(Tumbler& t, double dt) const;
    void updateSleep(Tumbler& t, double dt);
    bool collideTumblerWalls(int i);  // true if it pushed
    void collideTumblerFloor(int i);
    void landOnSide(int i);
    bool separateBallsFromTumblers();
    void settleTumblers();
    void stepBall(int ball, double dt);
    void keepSpeed(Vec3& midStepVelocity, double speed) const;
    void bounceOffTumblers(int ball, double gy, double dt, Vec3& v0);
    void moveBallKeepingEnergy(Ball& ball, const Vec3& to);
    void collideBallTumblers(int ball);
    void collideBallPairs();
    void collideBallLamp(Ball& ball);
    void ignite(int marble, const Vec3& at);
    void updateParticles(double dt);
    void emitSparks(const Vec3& at, const Vec3& normal, int count);
    void emitAsh(const Ball& marble);
    void wake(int tumbler);
    Particle* allocateParticle();

    Scene scene_;
    RoundCone shape_;
    MassProperties mass_;
    Vec3 comLocal_{0.0};  // centre of mass in the tumbler's local frame
    Vec3 inertiaCom_{0.0};
    std::vector<Tumbler> tumblers_;
    std::vector<Ball> balls_;
    std::vector<Particle> particles_;
    Rng rng_;
    double time_ = 0.0;
    double removedBallEnergy_ = 0.0;
    double substepDt_ = 0.0;  // the sub-step in effect (adaptive sub-steps change it)
    uint64_t steps_ = 0;
    uint64_t bodiesVersion_ = 0, particlesVersion_ = 0;
    bool bodiesMoved_ = false, particlesChanged_ = false;
    std::vector<int> gridCells_, gridStart_, gridCursor_, gridOrder_;  // broad phase scratch (ball pairs)
    // Ball pairs the last broad phase looked at (the step's work budget, substepsFor).
    static constexpr uint64_t kPairChecksUnknown = ~uint64_t(0);
    uint64_t pairChecks_ = kPairChecksUnknown;
    std::vector<Vec3> ballsBefore_;  // ball positions at the start of the sub-step (swept tests)

    struct Drag {
        int tumbler = -1;
        DragMode mode = DragMode::Translate;
        double planeY = 0.0;
        Vec3 offset{0.0};  // hit point − O at the start of a translate drag
    } drag_;
};

}  // namespace kiln::sim
