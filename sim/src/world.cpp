#include "kiln/sim/world.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>

namespace kiln::sim {

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr size_t kMaxParticles = 4096;
constexpr double kFireRate = 400.0;        // particles per second per fireball (SPEC §5)
constexpr double kFireLife = 0.45;
constexpr double kBurnDuration = 1.2;      // seconds a marble burns before turning to ash
constexpr double kTumblerRestitution = 0.5;

Mat3 skew(const Vec3& r) { return Mat3(0, r.z, -r.y, -r.z, 0, r.x, r.y, -r.x, 0); }  // column-major: [r]×

// Exact distance from X to a round cone with axis a0→a1 and end radii r0, r1.
double roundConeDistance(const Vec3& x, const Vec3& a0, const Vec3& a1, double r0, double r1) {
    Vec3 axis = a1 - a0;
    double h = glm::length(axis);
    if (r1 > r0) return roundConeDistance(x, a1, a0, r1, r0);
    if (h < 1e-12 || r0 - r1 >= h) return glm::length(x - a0) - r0;  // one sphere contains the other
    axis /= h;
    const Vec3 d = x - a0;
    const double y = glm::dot(d, axis);
    const double r = glm::length(d - y * axis);
    const double s = (r0 - r1) / h, c = std::sqrt(1.0 - s * s);
    const double k = -r * s + y * c;
    if (k < 0.0) return std::sqrt(r * r + y * y) - r0;
    if (k > c * h) return std::sqrt(r * r + (y - h) * (y - h)) - r1;
    return r * c + y * s - r0;
}

uint64_t fnv(uint64_t h, const void* data, size_t n) {
    const auto* p = static_cast<const unsigned char*>(data);
    for (size_t i = 0; i < n; ++i) h = (h ^ p[i]) * 1099511628211ull;
    return h;
}

}  // namespace

// ---- random numbers -----------------------------------------------------------

void Rng::reseed(uint64_t seed) {
    state_ = 0;
    inc_ = (seed << 1u) | 1u;
    next();
    state_ += 0x853c49e6748fea9bull + seed;
    next();
}

uint32_t Rng::next() {
    uint64_t old = state_;
    state_ = old * 6364136223846793005ull + inc_;
    uint32_t xorshifted = uint32_t(((old >> 18u) ^ old) >> 27u);
    uint32_t rot = uint32_t(old >> 59u);
    return (xorshifted >> rot) | (xorshifted << ((32 - rot) & 31));
}

Vec3 Rng::inUnitBall() {
    for (;;) {
        Vec3 p(uniform(-1, 1), uniform(-1, 1), uniform(-1, 1));
        if (glm::dot(p, p) <= 1.0) return p;
    }
}

Vec3 Rng::onUnitSphere() {
    for (;;) {
        Vec3 p = inUnitBall();
        double l = glm::length(p);
        if (l > 1e-3) return p / l;
    }
}

// ---- small pieces ---------------------------------------------------------------

void Tumbler::modelMatrix(float out[16]) const {
    const Mat3 r = rotation();
    for (int c = 0; c < 3; ++c) {
        for (int row = 0; row < 3; ++row) out[c * 4 + row] = float(r[c][row]);
        out[c * 4 + 3] = 0.0f;
    }
    out[12] = float(position.x), out[13] = float(position.y), out[14] = float(position.z), out[15] = 1.0f;
}

double Particle::radius() const {
    const double f = std::clamp(life / maxLife, 0.0, 1.0);
    return kind == ParticleKind::Ash ? size * (0.4 + 0.6 * f) : size * f;
}

Vec3 Particle::emission() const {
    const double f = std::clamp(life / maxLife, 0.0, 1.0);
    switch (kind) {
        case ParticleKind::Fire: return Vec3(4.0, 1.6, 0.4) * f;
        case ParticleKind::Spark: return Vec3(6.0, 4.0, 1.5) * f;
        case ParticleKind::Ash: {
            // Glows while large; once it has shrunk below 60 % it cools quickly to black.
            const double glow = std::clamp((f - 0.35) / 0.25, 0.0, 1.0);
            return Vec3(2.5, 0.9, 0.2) * glow * glow;
        }
    }
    return Vec3(0.0);
}

ConeSeparation roundConeSeparation(const Vec3& a0, const Vec3& a1, double ra0, double ra1, const Vec3& b0,
                                   const Vec3& b1, double rb0, double rb1) {
    // f(s) = dist(A's axis point at s, cone B) − r_A(s) is convex in s (PHYSICS.md):
    // golden-section search on s, exact round-cone distance for the inner minimum.
    auto f = [&](double s) { return roundConeDistance(a0 + s * (a1 - a0), b0, b1, rb0, rb1) - (ra0 + s * (ra1 - ra0)); };
    const double g = 0.6180339887498949;
    double lo = 0.0, hi = 1.0, x1 = hi - g * (hi - lo), x2 = lo + g * (hi - lo), f1 = f(x1), f2 = f(x2);
    for (int i = 0; i < 60; ++i) {
        if (f1 < f2) hi = x2, x2 = x1, f2 = f1, x1 = hi - g * (hi - lo), f1 = f(x1);
        else lo = x1, x1 = x2, f1 = f2, x2 = lo + g * (hi - lo), f2 = f(x2);
    }
    double s = 0.5 * (lo + hi), fs = f(s);
    if (f(0.0) < fs) s = 0.0, fs = f(0.0);
    if (f(1.0) < fs) s = 1.0, fs = f(1.0);
    const Vec3 onA = a0 + s * (a1 - a0);
    // The matching parameter on B: the axis point nearest to onA's projection.
    const Vec3 axisB = b1 - b0;
    const double len2 = glm::dot(axisB, axisB);
    const double u = len2 > 0 ? std::clamp(glm::dot(onA - b0, axisB) / len2, 0.0, 1.0) : 0.0;
    return {fs, s, u, onA, b0 + u * axisB};
}

// ---- world ----------------------------------------------------------------------

void World::reset(const Scene& scene) {
    scene_ = scene;
    const auto& ts = scene.tumblerShape;
    shape_ = RoundCone(ts.b, ts.t, ts.alpha);
    mass_ = shape_.massProperties(ts.mass);
    if (scene.physics.tumblerMode == TumblerMode::Accurate) {
        // A weighted base: the centre of mass sits h below O, and the inertia about it
        // is the uniform body's own (PHYSICS.md, "Rocking").
        comLocal_ = Vec3(0, -scene.physics.ballastH, 0);
        inertiaCom_ = mass_.inertiaCom;
    } else {
        // The seed's assumption: centre of mass at O.
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
    for (auto& m : scene.marbles) balls_.push_back({m.position, m.velocity, Vec3(0.0), m.radius, BallKind::Marble, m.color, 0.0});
    for (auto& f : scene.fireballs)
        balls_.push_back({f.position, f.velocity, Vec3(0.0), f.radius, BallKind::Fireball, f.color, 0.0});
    particles_.clear();
    fireAccumulator_.clear();
    rng_.reseed(scene.physics.seed);
    time_ = 0.0;
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

void World::step() {
    const int n = std::max(1, scene_.physics.substeps);
    const double dt = scene_.physics.dt / n;
    bodiesMoved_ = particlesChanged_ = false;
    for (int k = 0; k < n; ++k) substep(dt);
    updateParticles(scene_.physics.dt);
    time_ += scene_.physics.dt;
    ++steps_;
    if (bodiesMoved_) ++bodiesVersion_;
    if (particlesChanged_) ++particlesVersion_;
}

void World::substep(double dt) {
    for (int i = 0; i < int(tumblers_.size()); ++i) stepTumbler(i, dt);
    for (int a = 0; a < int(tumblers_.size()); ++a)
        for (int b = a + 1; b < int(tumblers_.size()); ++b) collideTumblerPair(a, b);
    for (int i = 0; i < int(tumblers_.size()); ++i) {
        collideTumblerWalls(i);
        collideTumblerFloor(i);
    }
    for (auto& ball : balls_) stepBall(ball, dt);
    if (!balls_.empty()) bodiesMoved_ = true;
    for (int i = 0; i < int(balls_.size()); ++i) {
        collideBallLamp(balls_[size_t(i)]);
        collideBallTumblers(i);
    }
    // Broad phase: balls sorted by x; only neighbours within the largest diameter are tested.
    std::vector<int> order(balls_.size());
    for (size_t i = 0; i < order.size(); ++i) order[i] = int(i);
    std::sort(order.begin(), order.end(), [&](int a, int b) {
        return balls_[size_t(a)].position.x < balls_[size_t(b)].position.x || (balls_[size_t(a)].position.x == balls_[size_t(b)].position.x && a < b);
    });
    double maxR = 0;
    for (auto& b : balls_) maxR = std::max(maxR, b.radius);
    for (size_t i = 0; i < order.size(); ++i)
        for (size_t j = i + 1; j < order.size(); ++j) {
            if (balls_[size_t(order[j])].position.x - balls_[size_t(order[i])].position.x > 2 * maxR) break;
            collideBallPair(order[i], order[j]);
        }
    // Contact pushes may nudge a ball past a wall: containment is exact per sphere.
    for (auto& b : balls_) b.position = glm::clamp(b.position, Vec3(b.radius - 1.0), Vec3(1.0 - b.radius));
    // Burning marbles turn to ash.
    for (size_t i = 0; i < balls_.size();) {
        Ball& b = balls_[i];
        if (b.kind == BallKind::Burning && (b.burnTime += dt) > kBurnDuration) {
            emitAsh(b);
            balls_.erase(balls_.begin() + long(i));
            continue;
        }
        ++i;
    }
}

void World::stepTumbler(int i, double dt) {
    Tumbler& t = tumblers_[size_t(i)];
    if (t.asleep || drag_.tumbler == i) return;
    const auto& ph = scene_.physics;
    const double m = tumblerMass(), b = shape_.b();
    Mat3 r = t.rotation();
    Vec3 g = t.position + r * comLocal_;
    Vec3 vG = t.velocity + glm::cross(t.angularVelocity, g - t.position);
    Vec3& w = t.angularVelocity;
    const Mat3 invI = inverseInertiaWorld(i);

    vG.y -= ph.gravity * dt;
    if (ph.tumblerMode == TumblerMode::Seed) {
        // The seed's restoring impulse −Δt·d at one unit above O.
        const Vec3 j = -dt * t.axis(), at = t.position + Vec3(0, 1, 0);
        vG += j / m;
        w += invI * glm::cross(at - g, j);
    }
    // Rolling contact at the lowest point of the lower sphere: the contact point's
    // velocity goes to zero (no slip, no penetration) through one 3D impulse j with
    // K·j = −v_c, K = (1/m)𝟙 − [r]× I⁻¹ [r]×. Only a pushing floor acts (j_y ≥ 0).
    const Vec3 contact(t.position.x, -1.0, t.position.z);
    const Vec3 rc = contact - g;
    const Vec3 vc = vG + glm::cross(w, rc);
    const Mat3 K = Mat3(1.0 / m) - skew(rc) * invI * skew(rc);
    const double det = glm::determinant(K);
    if (std::abs(det) > 1e-12) {
        const Vec3 j = glm::inverse(K) * (-vc);
        if (j.y >= 0.0) {
            vG += j / m;
            w += invI * glm::cross(rc, j);
        }
    }
    // Friction damps rocking and rolling (SPEC §4.1).
    if (ph.friction > 0) {
        const double wl = glm::length(w), dw = ph.friction * ph.gravity * dt / b;
        w = wl > dw ? w * ((wl - dw) / wl) : Vec3(0.0);
    }
    // Integrate the centre of mass and the orientation (world-frame ω).
    g += vG * dt;
    const Quat dq(0.0, w.x, w.y, w.z);
    t.orientation = glm::normalize(t.orientation + (dt * 0.5) * (dq * t.orientation));
    r = t.rotation();
    t.position = g - r * comLocal_;
    t.position.y = -1.0 + b;  // stays on the floor (SPEC §4.1)
    // Rolling without slipping fixes O's horizontal velocity by ω.
    t.velocity = Vec3(-b * w.z, 0.0, b * w.x);

    const double tilt = std::acos(std::clamp(t.axis().y, -1.0, 1.0));
    if (glm::length(t.velocity) < 2e-3 && glm::length(w) < 2e-2 && tilt < 0.02) {
        t.restTime += dt;
        if (t.restTime > 0.5) {
            t.asleep = true;
            t.velocity = w = Vec3(0.0);
        }
    } else {
        t.restTime = 0.0;
    }
    bodiesMoved_ = true;
}

void World::collideTumblerWalls(int i) {
    Tumbler& t = tumblers_[size_t(i)];
    const double decay = scene_.physics.wallDecay;
    const Vec3 centres[2] = {t.position, t.upperCentre(shape_)};
    const double radii[2] = {shape_.b(), shape_.t()};
    for (int axis : {0, 2}) {
        double push = 0.0;
        for (int k = 0; k < 2; ++k) {
            const double limit = 1.0 - radii[k];
            if (centres[k][axis] > limit) push = std::min(push, limit - centres[k][axis]);
            if (centres[k][axis] < -limit) push = std::max(push, -limit - centres[k][axis]);
        }
        if (push == 0.0) continue;
        t.position[axis] += push;
        const double sign = push < 0 ? 1.0 : -1.0;  // +1: the wall at +1
        // Reverse the wall-normal velocity (and the rolling spin that carries it).
        if (t.velocity[axis] * sign > 0) {
            t.velocity[axis] *= -decay;
            if (axis == 0) t.angularVelocity.z *= -decay;
            else t.angularVelocity.x *= -decay;
        }
        wake(i);
    }
}

void World::collideTumblerFloor(int i) {
    // Only the upper sphere can reach the floor (the toy fell over): hold it at the
    // floor, stop it, and let it right itself from there.
    Tumbler& t = tumblers_[size_t(i)];
    const Vec3 upper = t.upperCentre(shape_);
    const double floorGap = upper.y - shape_.t() - (-1.0);
    if (floorGap >= 0.0) return;
    const Vec3 axis = t.axis();
    // Rotate about the horizontal axis perpendicular to the tilt until the gap closes.
    Vec3 tiltAxis = glm::cross(axis, Vec3(0, 1, 0));
    const double len = glm::length(tiltAxis);
    if (len < 1e-9) return;
    tiltAxis /= len;
    const double lever = shape_.upperCentre();
    const double angle = -floorGap / std::max(lever, 1e-6);
    t.orientation = glm::normalize(glm::angleAxis(angle, tiltAxis) * t.orientation);
    t.velocity = Vec3(0.0);
    t.angularVelocity = Vec3(0.0);
}

void World::collideTumblerPair(int a, int b) {
    Tumbler& ta = tumblers_[size_t(a)];
    Tumbler& tb = tumblers_[size_t(b)];
    if (ta.asleep && tb.asleep) return;
    const double reach = 2.0 * (shape_.top() + shape_.b());
    if (glm::length(ta.position - tb.position) > reach) return;

    Vec3 n(0.0), h(0.0);
    double depth = 0.0;
    if (scene_.physics.tumblerContact == TumblerContact::Exact) {
        ConeSeparation sep = roundConeSeparation(ta.position, ta.upperCentre(shape_), shape_.b(), shape_.t(), tb.position,
                                                 tb.upperCentre(shape_), shape_.b(), shape_.t());
        if (sep.distance >= 0.0) return;
        const double rA = shape_.b() + sep.s * (shape_.t() - shape_.b());
        n = tumblerNormal(b, sep.onA) * -1.0;  // from A towards B
        const double dB = tumblerSdf(b, sep.onA);
        h = 0.5 * ((sep.onA + n * rA) + (sep.onA + n * dB));
        depth = -sep.distance;
    } else {
        // The seed's approximation: each end sphere against the other's exact SDF.
        int hits = 0;
        auto test = [&](int self, int other, const Vec3& centre, double radius, double sign) {
            const double d = tumblerSdf(other, centre);
            if (d - radius >= 0.0) return;
            const Vec3 g = tumblerNormal(other, centre);
            n += sign * g;
            h += centre - g * d;
            depth = std::max(depth, radius - d);
            ++hits;
            (void)self;
        };
        test(a, b, ta.position, shape_.b(), -1.0);
        test(a, b, ta.upperCentre(shape_), shape_.t(), -1.0);
        test(b, a, tb.position, shape_.b(), 1.0);
        test(b, a, tb.upperCentre(shape_), shape_.t(), 1.0);
        if (hits == 0) return;
        h /= double(hits);
    }
    double nl = glm::length(n);
    if (nl < 1e-9) {  // coincident: separate along x
        n = Vec3(ta.position.x <= tb.position.x ? 1.0 : -1.0, 0, 0);
        nl = 1.0;
    }
    n /= nl;
    // Separate on the floor plane, half each.
    Vec3 nh(n.x, 0.0, n.z);
    const double nhl = glm::length(nh);
    nh = nhl > 1e-9 ? nh / nhl : Vec3(1, 0, 0);
    ta.position -= nh * (0.5 * depth);
    tb.position += nh * (0.5 * depth);
    // Normal impulse from the relative velocity at the contact: the scalar form of
    // j = K⁻¹Δv along n, which stays defined when K itself is singular.
    const Vec3 vRel = pointVelocity(b, h) - pointVelocity(a, h);
    const double vn = glm::dot(vRel, n);
    if (vn < 0.0) {
        auto kOf = [&](int i) {
            const Vec3 r = h - centreOfMass(i);
            return 1.0 / tumblerMass() + glm::dot(n, glm::cross(inverseInertiaWorld(i) * glm::cross(r, n), r));
        };
        const double jn = -(1.0 + kTumblerRestitution) * vn / (kOf(a) + kOf(b));
        applyImpulse(a, h, -jn * n);
        applyImpulse(b, h, jn * n);
    }
    wake(a);
    wake(b);
}

void World::stepBall(Ball& ball, double dt) {
    const bool gravity = ball.kind != BallKind::Fireball;
    const Vec3 acc(0.0, gravity ? -scene_.physics.gravity : 0.0, 0.0);
    Vec3 v1 = ball.velocity + acc * dt;
    Vec3 x1 = ball.position + v1 * dt;
    const double limit = 1.0 - ball.radius;
    for (int k = 0; k < 3; ++k) {
        if (std::abs(x1[k]) <= limit) continue;
        // Penetrate, then mirror: the part of the step beyond the wall is reflected
        // back, as is the velocity. Energy swings within O(g·|v|·dt) per bounce and
        // shows no trend (PHYSICS.md); reflecting the velocity after the gravity kick
        // without mirroring the position gains energy at every bounce.
        const double wall = x1[k] > 0 ? limit : -limit;
        x1[k] = std::clamp(2.0 * wall - x1[k], -limit, limit);
        v1[k] = -v1[k];
        Vec3 normal(0.0);
        normal[k] = wall > 0 ? -1.0 : 1.0;
        ball.angularVelocity = glm::cross(normal, v1) / ball.radius;  // rolling on the wall
        if (ball.kind == BallKind::Fireball) emitSparks(x1 - normal * ball.radius, normal, 6);
    }
    ball.velocity = v1;
    ball.position = x1;
}

void World::collideBallLamp(Ball& ball) {
    const Vec3 c = scene_.lamp.center;
    const double reach = scene_.lamp.radius + ball.radius;
    const Vec3 d = ball.position - c;
    const double dist = glm::length(d);
    if (dist >= reach || ball.position.y >= 1.0 || dist < 1e-12) return;
    const Vec3 n = d / dist;
    ball.position = c + n * reach;
    ball.position.y = std::min(ball.position.y, 1.0 - ball.radius);
    const double vn = glm::dot(ball.velocity, n);
    if (vn < 0) ball.velocity -= 2.0 * vn * n;
    if (ball.kind == BallKind::Fireball) emitSparks(c + n * scene_.lamp.radius, n, 6);
}

void World::collideBallTumblers(int bi) {
    for (int i = 0; i < int(tumblers_.size()); ++i) resolveBallTumblerContact(bi, i);
}

bool World::resolveBallTumblerContact(int bi, int i) {
    Ball& ball = balls_[size_t(bi)];
    const Tumbler& t = tumblers_[size_t(i)];
    if (glm::length(ball.position - t.position) > shape_.top() + shape_.b() + ball.radius) return false;
    const double d = tumblerSdf(i, ball.position);
    if (d >= ball.radius) return false;
    const Vec3 n = tumblerNormal(i, ball.position);
    const Vec3 h = ball.position - d * n;  // the contact point on the surface
    ball.position += n * (ball.radius - d);
    const double vn = glm::dot(ball.velocity - pointVelocity(i, h), n);
    if (vn >= 0.0) return true;
    // Elastic two-body impulse: momentum and energy of ball + tumbler conserved.
    const Vec3 r = h - centreOfMass(i);
    const double k = 1.0 / ball.mass() + 1.0 / tumblerMass() +
                     glm::dot(n, glm::cross(inverseInertiaWorld(i) * glm::cross(r, n), r));
    const double jn = -2.0 * vn / k;
    ball.velocity += (jn / ball.mass()) * n;
    applyImpulse(i, h, -jn * n);
    wake(i);
    if (ball.kind == BallKind::Fireball) emitSparks(h, n, 10);
    return true;
}

void World::collideBallPair(int ai, int bi) {
    Ball& a = balls_[size_t(ai)];
    Ball& b = balls_[size_t(bi)];
    Vec3 d = b.position - a.position;
    const double reach = a.radius + b.radius;
    double dist = glm::length(d);
    if (dist >= reach) return;
    const Vec3 n = dist > 1e-12 ? d / dist : Vec3(1, 0, 0);
    const double ma = a.mass(), mb = b.mass();
    // Separate in proportion to the other's mass (the centre of mass stays put).
    const double pen = reach - dist;
    a.position -= n * (pen * mb / (ma + mb));
    b.position += n * (pen * ma / (ma + mb));
    const double vn = glm::dot(b.velocity - a.velocity, n);
    if (vn < 0) {
        const double j = -2.0 * vn / (1.0 / ma + 1.0 / mb);
        a.velocity -= (j / ma) * n;
        b.velocity += (j / mb) * n;
    }
    const bool aFire = a.kind == BallKind::Fireball, bFire = b.kind == BallKind::Fireball;
    if (aFire && b.kind == BallKind::Marble) ignite(bi, a.position + n * a.radius);
    if (bFire && a.kind == BallKind::Marble) ignite(ai, b.position - n * b.radius);
    if (aFire || bFire) emitSparks(a.position + n * a.radius, n, 8);
}

void World::ignite(int marble, const Vec3& at) {
    Ball& m = balls_[size_t(marble)];
    m.kind = BallKind::Burning;
    m.burnTime = 0.0;
    emitSparks(at, glm::normalize(m.position - at + Vec3(0, 1e-9, 0)), 12);
}

Particle* World::allocateParticle() {
    if (particles_.size() >= kMaxParticles) return nullptr;  // capped: bounded cost
    particles_.emplace_back();
    particlesChanged_ = true;
    return &particles_.back();
}

void World::emitSparks(const Vec3& at, const Vec3& normal, int count) {
    for (int i = 0; i < count; ++i) {
        Particle* p = allocateParticle();
        if (!p) return;
        p->kind = ParticleKind::Spark;
        p->position = at;
        p->velocity = (normal + 0.6 * rng_.inUnitBall()) * rng_.uniform(1.0, 3.0);
        p->maxLife = p->life = rng_.uniform(0.7, 1.3);
        p->size = 0.008;
    }
}

void World::emitAsh(const Ball& marble) {
    for (int i = 0; i < 60; ++i) {
        Particle* p = allocateParticle();
        if (!p) return;
        p->kind = ParticleKind::Ash;
        p->position = marble.position + marble.radius * rng_.inUnitBall();
        p->velocity = marble.velocity * 0.5 + 0.4 * rng_.inUnitBall();
        p->maxLife = p->life = rng_.uniform(0.7, 1.3);
        p->size = 0.012;
    }
}

void World::updateParticles(double dt) {
    // Fire: 400/s per fireball, inside it and denser near its centre.
    size_t fireball = 0;
    for (auto& b : balls_) {
        if (b.kind != BallKind::Fireball && b.kind != BallKind::Burning) continue;
        if (fireAccumulator_.size() <= fireball) fireAccumulator_.push_back(0.0);
        double& owed = fireAccumulator_[fireball++];
        owed += kFireRate * dt * (b.kind == BallKind::Burning ? 0.5 : 1.0);
        for (; owed >= 1.0; owed -= 1.0) {
            Particle* p = allocateParticle();
            if (!p) break;
            const Vec3 dir = rng_.onUnitSphere();
            const double u = rng_.uniform();
            p->kind = ParticleKind::Fire;
            p->position = b.position + dir * (b.radius * u * u);  // u² packs them near the centre
            p->velocity = b.velocity + Vec3(0.3 * rng_.uniform(-1, 1), rng_.uniform(0.4, 1.2), 0.3 * rng_.uniform(-1, 1));
            p->maxLife = p->life = kFireLife;
            p->size = b.radius * 0.35;
        }
    }
    for (size_t i = 0; i < particles_.size();) {
        Particle& p = particles_[i];
        p.life -= dt;
        if (p.life <= 0.0) {
            p = particles_.back();  // swap-remove: order stays deterministic
            particles_.pop_back();
            particlesChanged_ = true;
            continue;
        }
        if (p.kind != ParticleKind::Fire) {
            Vec3 drift = p.kind == ParticleKind::Ash ? 0.5 * rng_.inUnitBall() : Vec3(0.0);
            p.velocity += (Vec3(0, -scene_.physics.gravity * (p.kind == ParticleKind::Ash ? 0.15 : 1.0), 0) + drift) * dt;
        }
        p.position = glm::clamp(p.position + p.velocity * dt, Vec3(-1.0), Vec3(1.0));
        particlesChanged_ = true;
        ++i;
    }
}

void World::spawnMarble(const Vec3& position, const Vec3& velocity, double radius) {
    const double l = 1.0 - radius;
    balls_.push_back({glm::clamp(position, Vec3(-l), Vec3(l)), velocity, Vec3(0.0), radius, BallKind::Marble,
                      Vec3(0.2 + 0.6 * rng_.uniform(), 0.2 + 0.6 * rng_.uniform(), 0.2 + 0.6 * rng_.uniform()), 0.0});
    ++bodiesVersion_;
}

void World::spawnFireball(const Vec3& position, const Vec3& velocity, double radius) {
    const double l = 1.0 - radius;
    balls_.push_back({glm::clamp(position, Vec3(-l), Vec3(l)), velocity, Vec3(0.0), radius, BallKind::Fireball,
                      Vec3(1.0, 0.5, 0.1), 0.0});
    ++bodiesVersion_;
}

void World::spawnRandom(BallKind kind) {
    const Vec3 p(rng_.uniform(-0.7, 0.7), rng_.uniform(0.0, 0.6), rng_.uniform(-0.7, 0.7));
    const Vec3 v = rng_.onUnitSphere() * rng_.uniform(1.0, 3.0);
    if (kind == BallKind::Fireball) spawnFireball(p, v);
    else spawnMarble(p, v);
}

std::optional<RayHit> World::raycastTumblers(const Vec3& origin, const Vec3& direction) const {
    const Vec3 d = glm::normalize(direction);
    std::optional<RayHit> best;
    for (int i = 0; i < int(tumblers_.size()); ++i) {
        double t = 0.0;
        for (int step = 0; step < 256 && t < 20.0; ++step) {
            const Vec3 p = origin + t * d;
            const double dist = tumblerSdf(i, p);
            if (dist < 1e-5) {
                if (!best || t < best->distance) best = RayHit{i, t, p};
                break;
            }
            t += dist;
        }
    }
    return best;
}

DragMode World::beginDrag(const RayHit& hit) {
    drag_.tumbler = hit.tumbler;
    Tumbler& t = tumblers_[size_t(hit.tumbler)];
    // SPEC §4.4: below the centre of mass (y < −1 + b) translates, above rotates.
    drag_.mode = hit.point.y < -1.0 + shape_.b() ? DragMode::Translate : DragMode::Rotate;
    drag_.planeY = hit.point.y;
    drag_.offset = hit.point - t.position;
    t.velocity = t.angularVelocity = Vec3(0.0);
    wake(hit.tumbler);
    return drag_.mode;
}

void World::dragTo(const Vec3& o, const Vec3& dir) {
    if (drag_.tumbler < 0 || drag_.mode != DragMode::Translate || std::abs(dir.y) < 1e-9) return;
    const double s = (drag_.planeY - o.y) / dir.y;
    if (s <= 0) return;
    const Vec3 x = o + s * dir;
    Tumbler& t = tumblers_[size_t(drag_.tumbler)];
    const double l = 1.0 - shape_.b();
    t.position.x = std::clamp(x.x - drag_.offset.x, -l, l);
    t.position.z = std::clamp(x.z - drag_.offset.z, -l, l);
    collideTumblerWalls(drag_.tumbler);
    ++bodiesVersion_;
}

void World::dragRotate(double aboutX, double aboutZ) {
    if (drag_.tumbler < 0 || drag_.mode != DragMode::Rotate) return;
    Tumbler& t = tumblers_[size_t(drag_.tumbler)];
    const Quat next = glm::normalize(glm::angleAxis(aboutZ, Vec3(0, 0, 1)) * glm::angleAxis(aboutX, Vec3(1, 0, 0)) * t.orientation);
    if (std::acos(std::clamp((next * Vec3(0, 1, 0)).y, -1.0, 1.0)) > 1.3) return;  // no further than lying down
    t.orientation = next;
    // Rolling without slipping: turning by θ about z rolls the sphere −b·θ along x.
    t.position.x += -shape_.b() * aboutZ;
    t.position.z += shape_.b() * aboutX;
    collideTumblerWalls(drag_.tumbler);
    ++bodiesVersion_;
}

void World::endDrag() {
    if (drag_.tumbler >= 0) wake(drag_.tumbler);
    drag_ = {};
}

uint64_t World::stateHash() const {
    uint64_t h = 1469598103934665603ull;
    for (auto& t : tumblers_) {
        h = fnv(h, &t.position, sizeof t.position);
        h = fnv(h, &t.orientation, sizeof t.orientation);
        h = fnv(h, &t.velocity, sizeof t.velocity);
        h = fnv(h, &t.angularVelocity, sizeof t.angularVelocity);
    }
    for (auto& b : balls_) {
        h = fnv(h, &b.position, sizeof b.position);
        h = fnv(h, &b.velocity, sizeof b.velocity);
        h = fnv(h, &b.kind, sizeof b.kind);
    }
    for (auto& p : particles_) {
        h = fnv(h, &p.position, sizeof p.position);
        h = fnv(h, &p.life, sizeof p.life);
    }
    h = fnv(h, &time_, sizeof time_);
    return h;
}

double World::maxQuaternionError() const {
    double e = 0.0;
    for (auto& t : tumblers_) e = std::max(e, std::abs(glm::length(t.orientation) - 1.0));
    return e;
}

bool World::allFinite() const {
    auto ok = [](const Vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); };
    for (auto& t : tumblers_)
        if (!ok(t.position) || !ok(t.velocity) || !ok(t.angularVelocity) || !std::isfinite(glm::length(t.orientation)))
            return false;
    for (auto& b : balls_)
        if (!ok(b.position) || !ok(b.velocity)) return false;
    for (auto& p : particles_)
        if (!ok(p.position) || !ok(p.velocity)) return false;
    return true;
}

double World::maxContainmentViolation() const {
    double worst = 0.0;
    auto check = [&](const Vec3& c, double r) {
        for (int k = 0; k < 3; ++k) worst = std::max(worst, std::abs(c[k]) + r - 1.0);
    };
    for (auto& t : tumblers_) {
        check(t.position, shape_.b());
        check(t.upperCentre(shape_), shape_.t());
    }
    for (auto& b : balls_) check(b.position, b.radius);
    return worst;
}

}  // namespace kiln::sim
