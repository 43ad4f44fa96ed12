// world.cpp — the World: reset, the step / sub-step order, spawning, and the
// per-tumbler frame helpers (centre of mass, inertia, point velocity, SDF).
#include "internal.hpp"

namespace kiln::sim {

using namespace detail;

void World::reset(const Scene& scene) {
    scene_ = scene;
    pairChecks_ = kPairChecksUnknown;
    const auto& ts = scene.tumblerShape;
    shape_ = RoundCone(ts.b, ts.t, ts.alpha);
    mass_ = shape_.massProperties(ts.mass);
    if (scene.physics.tumblerMode == TumblerMode::Accurate) {
        // A weighted base: the centre of mass sits h below O, and the inertia about it
        // is I_G = I_O − m·y_G², the uniform body's inertia moved from O to its own
        // centroid by the parallel-axis theorem — the I_G of docs/physics.md's rocking example.
        comLocal_ = Vec3(0, -scene.physics.ballastH, 0);
        inertiaCom_ = mass_.inertiaCom;
    } else {
        // The course design's assumption: centre of mass at O.
        comLocal_ = Vec3(0.0);
        inertiaCom_ = mass_.inertiaOrigin;
    }
    tumblers_.clear();
    for (auto& spec : scene.tumblers) {
        Tumbler t;
        t.position = Vec3(spec.position.x, -1.0 + ts.b, spec.position.y);
        t.orientation = glm::angleAxis(spec.tilt.y, Vec3(0, 0, 1)) * glm::angleAxis(spec.tilt.x, Vec3(1, 0, 0));
        t.color = spec.color;
        tumblers_.push_back(t);
    }
    balls_.clear();
    for (auto& m : scene.marbles) balls_.push_back({m.position, m.velocity, Vec3(0.0), m.radius, BallKind::Marble, m.color});
    for (auto& f : scene.fireballs)
        balls_.push_back({f.position, f.velocity, Vec3(0.0), f.radius, BallKind::Fireball, f.color});
    particles_.clear();
    particles_.reserve(kMaxParticles);  // the pool: allocated once, never grows
    rng_.reseed(scene.physics.seed);
    time_ = 0.0;
    removedBallEnergy_ = 0.0;
    substepDt_ = scene.physics.dt / fewestSubsteps(scene.physics);  // what a calm first frame uses
    steps_ = 0;
    ++bodiesVersion_;
    ++particlesVersion_;
    drag_ = {};
}

Vec3 World::centreOfMass(int i) const {
    const Tumbler& t = tumblers_[size_t(i)];
    return t.position + t.rotation() * comLocal_;
}

Mat3 World::inverseInertiaWorld(int i) const {
    const Mat3 r = tumblers_[size_t(i)].rotation();
    const Mat3 inv(1.0 / inertiaCom_.x, 0, 0, 0, 1.0 / inertiaCom_.y, 0, 0, 0, 1.0 / inertiaCom_.z);
    return r * inv * glm::transpose(r);
}

Vec3 World::pointVelocity(int i, const Vec3& p) const {
    const Tumbler& t = tumblers_[size_t(i)];
    return t.velocity + glm::cross(t.angularVelocity, p - t.position);
}

Vec3 World::floorContact(int i) const {
    const Tumbler& t = tumblers_[size_t(i)];
    return Vec3(t.position.x, t.position.y - shape_.b(), t.position.z);
}

Mat3 World::rollingInertia(int i) const {
    const Mat3 R = tumblers_[size_t(i)].rotation();
    const Mat3 IG = R * Mat3(inertiaCom_.x, 0, 0, 0, inertiaCom_.y, 0, 0, 0, inertiaCom_.z) * glm::transpose(R);
    const Vec3 r = centreOfMass(i) - floorContact(i);
    return IG + tumblerMass() * (glm::dot(r, r) * Mat3(1.0) - glm::outerProduct(r, r));
}

double World::rollingInverseMass(int i, const Vec3& p, const Vec3& n) const {
    const Vec3 rn = glm::cross(p - floorContact(i), n);
    return glm::dot(rn, glm::inverse(rollingInertia(i)) * rn);
}

void World::applyRollingImpulse(int i, const Vec3& p, const Vec3& j) {
    // Angular momentum about the contact point changes by (p − P) × j; the floor's own
    // impulse acts at P and has no moment there. The body then turns about P.
    Tumbler& t = tumblers_[size_t(i)];
    t.angularVelocity += glm::inverse(rollingInertia(i)) * glm::cross(p - floorContact(i), j);
    t.velocity = shape_.b() * Vec3(-t.angularVelocity.z, 0.0, t.angularVelocity.x);
}

double World::tumblerEnergy(int i) const {
    const Vec3& w = tumblers_[size_t(i)].angularVelocity;
    return 0.5 * glm::dot(w, rollingInertia(i) * w) + tumblerMass() * scene_.physics.gravity * centreOfMass(i).y;
}

double World::tumblerJellett(int i) const {
    const Tumbler& t = tumblers_[size_t(i)];
    const Mat3 R = t.rotation();
    const Mat3 IG = R * Mat3(inertiaCom_.x, 0, 0, 0, inertiaCom_.y, 0, 0, 0, inertiaCom_.z) * glm::transpose(R);
    return glm::dot(IG * t.angularVelocity, centreOfMass(i) - floorContact(i));
}

double World::totalEnergy() const {
    double e = 0.0;
    for (int i = 0; i < int(tumblers_.size()); ++i) e += tumblerEnergy(i);
    for (int i = 0; i < int(balls_.size()); ++i) e += balls_[size_t(i)].mass() * ballEnergy(i);
    return e;
}

void World::applyImpulse(int i, const Vec3& p, const Vec3& j) {
    Tumbler& t = tumblers_[size_t(i)];
    const Vec3 g = centreOfMass(i);
    Vec3 vG = t.velocity + glm::cross(t.angularVelocity, g - t.position);
    vG += j / tumblerMass();
    t.angularVelocity += inverseInertiaWorld(i) * glm::cross(p - g, j);
    t.velocity = vG + glm::cross(t.angularVelocity, t.position - g);
}

double World::tumblerSdf(int i, const Vec3& p) const {
    const Tumbler& t = tumblers_[size_t(i)];
    return shape_.sdf(glm::transpose(t.rotation()) * (p - t.position));
}

Vec3 World::tumblerNormal(int i, const Vec3& p) const {
    const Tumbler& t = tumblers_[size_t(i)];
    const Mat3 r = t.rotation();
    return r * shape_.gradient(glm::transpose(r) * (p - t.position));
}

void World::wake(int i) {
    tumblers_[size_t(i)].asleep = false;
    tumblers_[size_t(i)].restTime = 0.0;
}

void World::settleTumblers() {
    // A wall push can move a tumbler back into its neighbour: repeat pairs + walls (up to
    // 8 passes) until a pass finds no pair overlapping by more than 0.1 mm and moves no
    // tumbler off a wall. Walls always run last, so containment is exact regardless.
    for (int pass = 0; pass < 8; ++pass) {
        double deepest = 0.0;
        for (int a = 0; a < int(tumblers_.size()); ++a)
            for (int b = a + 1; b < int(tumblers_.size()); ++b) deepest = std::min(deepest, resolveTumblerPair(a, b));
        bool pushed = false;
        for (int i = 0; i < int(tumblers_.size()); ++i) pushed = collideTumblerWalls(i) || pushed;
        if (deepest > -1e-4 && !pushed) break;
    }
}

// Adaptive sub-steps are never longer than kMaxFixedSubstep: a body that starts the frame
// slow may be hit and spun fast within it (scene.cpp refuses a ceiling that cannot reach
// this; a fixed count is the scene's to choose, and the scene file holds it to the same
// bound).
int World::fewestSubsteps(const Scene::Physics& p) {
    const int n = std::max(1, p.substeps);
    if (p.maxSubsteps <= n) return n;
    return std::min(p.maxSubsteps, std::max(n, int(std::ceil(p.dt / kMaxFixedSubstep - 1e-9))));
}

int World::substepsFor(double frame) const {
    // Adaptive sub-stepping: at least the scene's count, more when a body would move
    // further per sub-step than the contacts can follow — a tumbler point more than
    // kMaxTumblerMove (a quarter of the upper radius), a ball more than half its radius;
    // at most physics.max_substeps, never longer than kMaxFixedSubstep.
    // At the shipped Δt nothing triggers it; at 1/15 s it keeps contacts resolvable.
    constexpr double kMaxTumblerMove = 0.025;
    const double reach = 2.0 * shape_.b() + shape_.top();  // |X − P| for any body point X
    double need = 0.0;
    for (auto& t : tumblers_)
        if (!t.asleep) need = std::max(need, glm::length(t.angularVelocity) * reach * frame / kMaxTumblerMove);
    for (auto& b : balls_) {
        const double speed = glm::length(b.velocity) + scene_.physics.gravity * frame;
        need = std::max(need, speed * frame / (0.5 * b.radius));
    }
    const int n = fewestSubsteps(scene_.physics);
    const int wanted = std::clamp(int(std::ceil(std::min(need, 1e6))), n, std::max(n, scene_.physics.maxSubsteps));
    // Bounded work per step, whatever the scene asks: sub-steps × (ball-tumbler pairs +
    // ball pairs the broad phase looked at last + tumbler pairs) stays within
    // kWorkPerStep (~40-80 ms here). A crowded scene at the count limits (scene.hpp) with
    // fast balls gets fewer sub-steps, not a frozen frame; the shipped scene (~100 units
    // a sub-step) never comes near it.
    constexpr double kWorkPerStep = double(1 << 22);
    const double balls = double(balls_.size()), tumblers = double(tumblers_.size());
    // Before the first broad phase its cost is unknown: assume every pair.
    const double pairs = pairChecks_ == kPairChecksUnknown ? balls * (balls - 1.0) / 2.0 : double(pairChecks_);
    const double perSubstep = balls * (tumblers + 1.0) + tumblers * tumblers + pairs + 1.0;
    return std::min(wanted, std::max(1, int(kWorkPerStep / perSubstep)));
}

void World::step() {
    const int n = substepsFor(scene_.physics.dt);
    const double dt = scene_.physics.dt / n;
    if (dt != substepDt_) {
        // Semi-implicit Euler carries the mid-step velocity u = v − ½gΔt·ŷ (what E′ =
        // ½|u|² + g·y counts): keep u when the sub-step changes, so the switch costs no
        // energy (v itself shifts by ½g·(Δt_new − Δt_old)).
        for (Ball& b : balls_)
            if (b.kind != BallKind::Fireball) b.velocity.y += 0.5 * scene_.physics.gravity * (dt - substepDt_);
        substepDt_ = dt;
    }
    bodiesMoved_ = particlesChanged_ = false;
    for (int k = 0; k < n; ++k) substep(dt);
    updateParticles(scene_.physics.dt);
    time_ += scene_.physics.dt;
    ++steps_;
    if (bodiesMoved_) ++bodiesVersion_;
    if (particlesChanged_) ++particlesVersion_;
}

void World::substep(double dt) {
    // Order (each correction runs after the ones it could undo): integrate; a toppled
    // tumbler rolls back onto its lower sphere (rotation + rolling shift); tumbler pairs
    // separate (horizontal); the walls push last, so tumblers always end inside.
    for (int i = 0; i < int(tumblers_.size()); ++i) stepTumbler(i, dt);
    for (int i = 0; i < int(tumblers_.size()); ++i) collideTumblerFloor(i);
    settleTumblers();
    ballsBefore_.resize(balls_.size());
    for (size_t i = 0; i < balls_.size(); ++i) ballsBefore_[i] = balls_[i].position;
    for (int i = 0; i < int(balls_.size()); ++i) stepBall(i, dt);
    if (!balls_.empty()) bodiesMoved_ = true;
    for (int i = 0; i < int(balls_.size()); ++i) {
        collideBallLamp(balls_[size_t(i)]);  // only a ball that started inside the dome
        collideBallTumblers(i);
    }
    collideBallPairs();
    // Contact pushes may nudge a ball past a wall or back into a tumbler: walls first
    // (exact per sphere, and paid for: a ball lifted off the floor by the clamp pays the
    // height from its speed), then tumblers give way where a ball has nowhere to go.
    for (auto& b : balls_) moveBallKeepingEnergy(b, glm::clamp(b.position, Vec3(b.radius - 1.0), Vec3(1.0 - b.radius)));
    if (separateBallsFromTumblers()) settleTumblers();
    // Burning marbles turn to ash.
    for (size_t i = 0; i < balls_.size();) {
        Ball& b = balls_[i];
        if (b.kind == BallKind::Burning && (b.burnTime += dt) > kBurnDuration) {
            emitAsh(b);
            removedBallEnergy_ += b.mass() * ballEnergy(int(i));
            balls_.erase(balls_.begin() + long(i));
            continue;
        }
        ++i;
    }
}

void World::spawnMarble(const Vec3& position, const Vec3& velocity, double radius) {
    const double l = 1.0 - radius;
    Vec3 color;
    for (int k = 0; k < 3; ++k) color[k] = 0.2 + 0.6 * rng_.uniform();  // sequenced: deterministic
    balls_.push_back({glm::clamp(position, Vec3(-l), Vec3(l)), velocity, Vec3(0.0), radius, BallKind::Marble, color});
    ++bodiesVersion_;
}

void World::spawnFireball(const Vec3& position, const Vec3& velocity, double radius) {
    const double l = 1.0 - radius;
    balls_.push_back({glm::clamp(position, Vec3(-l), Vec3(l)), velocity, Vec3(0.0), radius, BallKind::Fireball,
                      Vec3(1.0, 0.5, 0.1)});
    ++bodiesVersion_;
}

void World::spawnRandom(BallKind kind) {
    // A held key spawns every frame: the count stays within what a scene file may ask
    // for, so a step stays bounded (scene.hpp's limits).
    if (balls_.size() >= kMaxMarbles + kMaxFireballs) return;
    Vec3 p;  // one draw per statement: argument evaluation order is unspecified
    p.x = rng_.uniform(-0.7, 0.7);
    p.y = rng_.uniform(0.0, 0.6);
    p.z = rng_.uniform(-0.7, 0.7);
    const Vec3 dir = rng_.onUnitSphere();
    const Vec3 v = dir * rng_.uniform(1.0, 3.0);
    if (kind == BallKind::Fireball) spawnFireball(p, v);
    else spawnMarble(p, v);
}
}  // namespace kiln::sim
