#include "kiln/sim/world.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

namespace kiln::sim {

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kFireRate = 400.0;        // particles per second per fireball (SPEC §5)
constexpr double kFireLife = 0.45;
constexpr double kTumblerRestitution = 0.5;

Mat3 skew(const Vec3& r) { return Mat3(0, r.z, -r.y, -r.z, 0, r.x, r.y, -r.x, 0); }  // column-major: [r]×

// Distance between segments p0p1 and q0q1 (Ericson, Real-Time Collision Detection 5.1.9).
double segmentDistance(const Vec3& p0, const Vec3& p1, const Vec3& q0, const Vec3& q1) {
    const Vec3 d1 = p1 - p0, d2 = q1 - q0, r = p0 - q0;
    const double a = glm::dot(d1, d1), e = glm::dot(d2, d2), f = glm::dot(d2, r);
    double s = 0, t = 0;
    if (a <= 1e-24 && e <= 1e-24) return glm::length(r);
    if (a <= 1e-24) {
        t = std::clamp(f / e, 0.0, 1.0);
    } else {
        const double c = glm::dot(d1, r);
        if (e <= 1e-24) {
            s = std::clamp(-c / a, 0.0, 1.0);
        } else {
            const double b = glm::dot(d1, d2), denom = a * e - b * b;
            s = denom > 1e-24 ? std::clamp((b * f - c * e) / denom, 0.0, 1.0) : 0.0;
            t = (b * s + f) / e;
            if (t < 0.0) t = 0.0, s = std::clamp(-c / a, 0.0, 1.0);
            else if (t > 1.0) t = 1.0, s = std::clamp((b - c) / a, 0.0, 1.0);
        }
    }
    return glm::length(p0 + s * d1 - (q0 + t * d2));
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
        Vec3 p;  // one draw per statement: argument evaluation order is unspecified
        p.x = uniform(-1, 1);
        p.y = uniform(-1, 1);
        p.z = uniform(-1, 1);
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

Vec3 Ball::albedo() const {
    if (kind != BallKind::Burning) return color;
    return color * (1.0 - std::min(1.0, burnTime / kBurnDuration));
}

Vec3 Ball::emissiveColor() const {
    switch (kind) {
        case BallKind::Marble: return Vec3(0.0);
        case BallKind::Fireball: return color;
        case BallKind::Burning: return Vec3(1.0, 0.4, 0.1);
    }
    return Vec3(0.0);
}

double Ball::emissiveStrength() const {
    switch (kind) {
        case BallKind::Marble: return 0.0;
        case BallKind::Fireball: return 6.0;
        case BallKind::Burning: return 3.0 * (1.0 - 0.7 * std::min(1.0, burnTime / kBurnDuration));
    }
    return 0.0;
}

Vec3 solveImpulse(const Mat3& K, const Vec3& dv) {
    const double tr = K[0][0] + K[1][1] + K[2][2];
    if (!(tr > 0.0) || !std::isfinite(tr)) return Vec3(0.0);
    const double det = glm::determinant(K);
    // Well conditioned relative to its scale (det ~ (tr/3)³ for an isotropic K).
    const double scale = tr / 3.0;
    if (det > 1e-9 * scale * scale * scale) return glm::inverse(K) * dv;
    // (Nearly) singular: the pseudo-inverse through a Jacobi eigen-decomposition,
    // dropping eigenvalues below 1e-9·λ_max — the minimum-norm least-squares impulse.
    double a[3][3];
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) a[r][c] = 0.5 * (K[c][r] + K[r][c]);
    double v[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    for (int sweep = 0; sweep < 50; ++sweep) {
        const double off = a[0][1] * a[0][1] + a[0][2] * a[0][2] + a[1][2] * a[1][2];
        if (off < 1e-30 * tr * tr) break;
        for (int p = 0; p < 2; ++p)
            for (int q = p + 1; q < 3; ++q) {
                if (a[p][q] == 0.0) continue;
                const double theta = 0.5 * (a[q][q] - a[p][p]) / a[p][q];
                const double t = (theta >= 0 ? 1.0 : -1.0) / (std::abs(theta) + std::sqrt(theta * theta + 1.0));
                const double c = 1.0 / std::sqrt(t * t + 1.0), sn = t * c;
                for (int k = 0; k < 3; ++k) {  // A ← Jᵀ A J
                    const double akp = a[k][p], akq = a[k][q];
                    a[k][p] = c * akp - sn * akq;
                    a[k][q] = sn * akp + c * akq;
                }
                for (int k = 0; k < 3; ++k) {
                    const double apk = a[p][k], aqk = a[q][k];
                    a[p][k] = c * apk - sn * aqk;
                    a[q][k] = sn * apk + c * aqk;
                }
                for (int k = 0; k < 3; ++k) {  // V ← V J
                    const double vkp = v[k][p], vkq = v[k][q];
                    v[k][p] = c * vkp - sn * vkq;
                    v[k][q] = sn * vkp + c * vkq;
                }
            }
    }
    const double lmax = std::max({a[0][0], a[1][1], a[2][2]});
    Vec3 j(0.0);
    for (int e = 0; e < 3; ++e) {
        const double lambda = a[e][e];
        if (!(lambda > 1e-9 * lmax)) continue;
        const Vec3 ve(v[0][e], v[1][e], v[2][e]);
        j += (glm::dot(ve, dv) / lambda) * ve;
    }
    return j;
}

// ---- world ----------------------------------------------------------------------

void World::reset(const Scene& scene) {
    scene_ = scene;
    const auto& ts = scene.tumblerShape;
    shape_ = RoundCone(ts.b, ts.t, ts.alpha);
    mass_ = shape_.massProperties(ts.mass);
    if (scene.physics.tumblerMode == TumblerMode::Accurate) {
        // A weighted base: the centre of mass sits h below O, and the inertia about it
        // is I_G = I_O − m·y_G², the uniform body's inertia moved from O to its own
        // centroid by the parallel-axis theorem — the I_G of PHYSICS.md's rocking example.
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
    for (auto& m : scene.marbles) balls_.push_back({m.position, m.velocity, Vec3(0.0), m.radius, BallKind::Marble, m.color});
    for (auto& f : scene.fireballs)
        balls_.push_back({f.position, f.velocity, Vec3(0.0), f.radius, BallKind::Fireball, f.color});
    particles_.clear();
    particles_.reserve(kMaxParticles);  // the pool: allocated once, never grows
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
        for (int b = a + 1; b < int(tumblers_.size()); ++b) resolveTumblerPair(a, b);
    for (int i = 0; i < int(tumblers_.size()); ++i) {
        collideTumblerWalls(i);
        collideTumblerFloor(i);
    }
    ballsBefore_.resize(balls_.size());
    for (size_t i = 0; i < balls_.size(); ++i) ballsBefore_[i] = balls_[i].position;
    for (auto& ball : balls_) stepBall(ball, dt);
    if (!balls_.empty()) bodiesMoved_ = true;
    for (int i = 0; i < int(balls_.size()); ++i) {
        collideBallLamp(balls_[size_t(i)]);
        collideBallTumblers(i);
    }
    collideBallPairs();
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
    const Vec3 j = solveImpulse(K, -vc);
    if (j.y >= 0.0) {
        vG += j / m;
        w += invI * glm::cross(rc, j);
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

    // Sleep after 0.5 s below the thresholds: upright at rest, or lying on the floor
    // (the floor contact zeroes it every sub-step). A rocking tumbler passes through
    // ω ≈ 0 only for an instant, so the continuous 0.5 s keeps it awake.
    if (glm::length(t.velocity) < 2e-3 && glm::length(w) < 2e-2) {
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
    // Only the upper sphere can reach the floor (the toy fell over): it lies there when
    // axis·y = (t − b)/y_t (≈ 110° for the default shape). Rotate it back exactly onto
    // the floor about the horizontal axis of its tilt, stop it, and let gravity (or the
    // seed's restoring impulse) right it from there.
    Tumbler& t = tumblers_[size_t(i)];
    const double cosLying = (shape_.t() - shape_.b()) / shape_.upperCentre();
    const Vec3 axis = t.axis();
    if (axis.y >= cosLying) return;
    Vec3 tiltAxis = glm::cross(axis, Vec3(0, 1, 0));  // rotating about it raises the axis
    const double len = glm::length(tiltAxis);
    if (len < 1e-12) tiltAxis = Vec3(1, 0, 0);  // upside down: any horizontal axis
    else tiltAxis /= len;
    const double angle = std::acos(std::clamp(axis.y, -1.0, 1.0)) - std::acos(cosLying);
    t.orientation = glm::normalize(glm::angleAxis(angle, tiltAxis) * t.orientation);
    t.velocity = Vec3(0.0);
    t.angularVelocity = Vec3(0.0);
}

double World::resolveTumblerPair(int a, int b) {
    Tumbler& ta = tumblers_[size_t(a)];
    Tumbler& tb = tumblers_[size_t(b)];
    const double inf = std::numeric_limits<double>::infinity();
    if (ta.asleep && tb.asleep) return inf;
    const double reach = 2.0 * (shape_.top() + shape_.b());
    if (glm::length(ta.position - tb.position) > reach) return inf;

    const Vec3 ua = ta.upperCentre(shape_), ub = tb.upperCentre(shape_);
    const double rb = shape_.b(), rt = shape_.t();
    // Cheap rejection: every point of a body is within b of its axis segment.
    if (segmentDistance(ta.position, ua, tb.position, ub) > 2.0 * rb) return inf;
    Vec3 n(0.0), h(0.0);
    double separation = 0.0;
    if (scene_.physics.tumblerContact == TumblerContact::Exact) {
        // min over s,u of |P_A(s) − P_B(u)| − r_A(s) − r_B(u): contact at the midpoint of
        // the two witness points, normal along the line between the axis points.
        const ConeSeparation sep = roundConeSeparation(ta.position, ua, rb, rt, tb.position, ub, rb, rt);
        separation = sep.distance;
        if (separation >= 0.0) return separation;
        n = sep.normal;
        h = 0.5 * (sep.witnessA + sep.witnessB);
    } else {
        // The seed's approximation: each end sphere against the other's exact SDF;
        // contact points and normals averaged over the spheres that touch.
        int hits = 0;
        separation = inf;
        auto test = [&](int other, const Vec3& centre, double radius, double sign) {
            const double d = tumblerSdf(other, centre);
            separation = std::min(separation, d - radius);
            if (d - radius >= 0.0) return;
            const Vec3 g = tumblerNormal(other, centre);
            n += sign * g;  // sign makes it point from A to B
            h += centre - g * d;
            ++hits;
        };
        test(b, ta.position, rb, -1.0);
        test(b, ua, rt, -1.0);
        test(a, tb.position, rb, 1.0);
        test(a, ub, rt, 1.0);
        if (hits == 0) return separation;
        h /= double(hits);
        const double nl = glm::length(n);
        n = nl > 1e-9 ? n / nl : Vec3(0.0);
    }
    if (glm::length(n) < 0.5) {  // coincident: no direction; separate along x
        n = Vec3(ta.position.x <= tb.position.x ? 1.0 : -1.0, 0, 0);
        if (ta.position.x == tb.position.x) n = Vec3(a < b ? 1.0 : -1.0, 0, 0);
    }
    // Separate on the floor plane, half each (both stay on the floor).
    Vec3 nh(n.x, 0.0, n.z);
    const double nhl = glm::length(nh);
    nh = nhl > 1e-9 ? nh / nhl : Vec3(1, 0, 0);
    const double depth = std::min(-separation, 2.0 * shape_.b());
    ta.position -= nh * (0.5 * depth);
    tb.position += nh * (0.5 * depth);
    // Normal impulse from the relative velocity at the contact: the scalar form of
    // j = K⁻¹Δv along n (n·K·n > 0 always, so it never divides by zero).
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
    return separation;
}

void World::stepBall(Ball& ball, double dt) {
    const double gy = ball.kind == BallKind::Fireball ? 0.0 : -scene_.physics.gravity;
    const Vec3 v0 = ball.velocity, x0 = ball.position;
    Vec3 v1 = v0;
    v1.y += gy * dt;
    Vec3 x1 = x0 + v1 * dt;
    const double limit = 1.0 - ball.radius;
    for (int k = 0; k < 3; ++k) {
        if (std::abs(x1[k]) <= limit) continue;
        // Time-symmetric bounce: a step that would cross the wall becomes the time
        // reverse of the step that came in, v₁ = −v₀, x₁ = x₀ + v₁Δt. It keeps E′ =
        // ½v² + g·y − ½gΔt·v_y exactly (PHYSICS.md), never lets the ball through (it
        // moves away from the wall from inside), and needs no sub-step time of impact.
        const double wall = x1[k] > 0 ? limit : -limit;
        v1[k] = -v0[k];
        x1[k] = x0[k] + v1[k] * dt;
        // A ball creeping along the floor (|v_y| < gΔt) may still cross, and one moving
        // more than the box per step would cross the opposite wall: hold it inside.
        x1[k] = std::clamp(x1[k], -limit, limit);
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
    for (int i = 0; i < int(tumblers_.size()); ++i) {
        Ball& ball = balls_[size_t(bi)];
        // A fast ball (moved more than its radius this sub-step) could jump over a
        // tumbler: conservative advancement along its path finds the first touch.
        const Vec3 from = ballsBefore_[size_t(bi)], path = ball.position - from;
        const double len = glm::length(path);
        if (len > ball.radius) {
            const Tumbler& t = tumblers_[size_t(i)];
            // Bounding sphere about O (every point of the body is within y_t + t of it).
            const double s = std::clamp(glm::dot(t.position - from, path) / (len * len), 0.0, 1.0);
            if (glm::length(from + s * path - t.position) < shape_.top() + ball.radius) {
                double along = 0.0;  // metres along the path
                for (int iter = 0; iter < 64 && along < len; ++iter) {
                    const double d = tumblerSdf(i, from + path * (along / len)) - ball.radius;
                    if (d < 1e-4) {
                        // Touching: stop a hair inside, so the contact below resolves it.
                        ball.position = from + path * (std::min(len, along + 2e-4) / len);
                        break;
                    }
                    along += d;
                }
            }
        }
        resolveBallTumblerContact(bi, i);
    }
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

void World::collideBallPairs() {
    const int n = int(balls_.size());
    if (n < 2) return;
    // Uniform grid over the box, cell ≥ the largest diameter: a ball can only touch
    // balls in its own and the 26 neighbouring cells. Counting sort keeps it O(n) and
    // deterministic (pairs are visited in ball index order).
    double maxR = 0;
    for (auto& b : balls_) maxR = std::max(maxR, b.radius);
    const int dim = std::clamp(int(2.0 / (2.0 * maxR)), 1, 64);
    const double inv = dim / 2.0;
    auto cellOf = [&](const Vec3& p, int axis) { return std::clamp(int((p[axis] + 1.0) * inv), 0, dim - 1); };
    gridCells_.resize(size_t(n));
    gridStart_.assign(size_t(dim) * dim * dim + 1, 0);
    gridOrder_.resize(size_t(n));
    for (int i = 0; i < n; ++i) {
        const Vec3& p = balls_[size_t(i)].position;
        gridCells_[size_t(i)] = (cellOf(p, 0) * dim + cellOf(p, 1)) * dim + cellOf(p, 2);
        ++gridStart_[size_t(gridCells_[size_t(i)]) + 1];
    }
    for (size_t c = 1; c < gridStart_.size(); ++c) gridStart_[c] += gridStart_[c - 1];
    gridCursor_.assign(gridStart_.begin(), gridStart_.end() - 1);
    for (int i = 0; i < n; ++i) gridOrder_[size_t(gridCursor_[size_t(gridCells_[size_t(i)])]++)] = i;
    // Each ball against later balls in its own cell, and against every ball in the 13
    // "forward" neighbour cells (the other 13 see this cell as their forward one).
    for (int i = 0; i < n; ++i) {
        const int c = gridCells_[size_t(i)];
        const int cx = c / (dim * dim), cy = (c / dim) % dim, cz = c % dim;
        for (int k = gridStart_[size_t(c)]; k < gridStart_[size_t(c) + 1]; ++k) {
            const int j = gridOrder_[size_t(k)];
            if (j > i) resolveBallBallContact(i, j);
        }
        for (int dx = 0; dx <= 1; ++dx)
            for (int dy = dx ? -1 : 0; dy <= 1; ++dy)
                for (int dz = (dx || dy) ? -1 : 1; dz <= 1; ++dz) {
                    const int x = cx + dx, y = cy + dy, z = cz + dz;
                    if (x >= dim || y < 0 || y >= dim || z < 0 || z >= dim) continue;
                    const int cell = (x * dim + y) * dim + z;
                    for (int k = gridStart_[size_t(cell)]; k < gridStart_[size_t(cell) + 1]; ++k)
                        resolveBallBallContact(i, gridOrder_[size_t(k)]);
                }
    }
}

bool World::resolveBallBallContact(int ai, int bi) {
    Ball& a = balls_[size_t(ai)];
    Ball& b = balls_[size_t(bi)];
    Vec3 d = b.position - a.position;
    const double reach = a.radius + b.radius;
    const double dist2 = glm::dot(d, d);
    if (dist2 >= reach * reach) return false;
    const double dist = std::sqrt(dist2);
    // Coincident centres: no direction; separate along x (deterministic by index).
    const Vec3 n = dist > 1e-12 ? d / dist : Vec3(ai < bi ? 1.0 : -1.0, 0, 0);
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
    const Vec3 at = a.position + n * a.radius;
    if (aFire && b.kind == BallKind::Marble) ignite(bi, at);
    if (bFire && a.kind == BallKind::Marble) ignite(ai, at);
    if ((aFire || bFire) && vn < 0) emitSparks(at, n, 8);
    return true;
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
        const Vec3 spread = rng_.inUnitBall();
        p->velocity = (normal + 0.6 * spread) * rng_.uniform(1.0, 3.0);
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
    for (auto& b : balls_) {
        if (b.kind != BallKind::Fireball && b.kind != BallKind::Burning) continue;
        double& owed = b.fireOwed;
        owed += kFireRate * dt * (b.kind == BallKind::Burning ? 0.5 : 1.0);
        for (; owed >= 1.0; owed -= 1.0) {
            Particle* p = allocateParticle();
            if (!p) {
                owed = 0.0;  // the pool is full: drop them rather than owe a burst
                break;
            }
            const Vec3 dir = rng_.onUnitSphere();
            const double u = rng_.uniform();
            p->kind = ParticleKind::Fire;
            p->position = b.position + dir * (b.radius * u * u);  // u² packs them near the centre
            Vec3 up;
            up.x = 0.3 * rng_.uniform(-1, 1);
            up.y = rng_.uniform(0.4, 1.2);
            up.z = 0.3 * rng_.uniform(-1, 1);
            p->velocity = b.velocity + up;
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
    Vec3 p;  // one draw per statement: argument evaluation order is unspecified
    p.x = rng_.uniform(-0.7, 0.7);
    p.y = rng_.uniform(0.0, 0.6);
    p.z = rng_.uniform(-0.7, 0.7);
    const Vec3 dir = rng_.onUnitSphere();
    const Vec3 v = dir * rng_.uniform(1.0, 3.0);
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
    // SPEC §4.4: a hit below the centre of mass translates, above rotates (the seed's
    // centre of mass is O at y = −1 + b; accurate mode's sits ballast_h lower).
    drag_.mode = hit.point.y < centreOfMass(hit.tumbler).y ? DragMode::Translate : DragMode::Rotate;
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
    const uint32_t rngProbe = Rng(rng_).next();  // the generator's position, not its internals
    h = fnv(h, &rngProbe, sizeof rngProbe);
    return h;
}

double World::ballEnergy(int i) const {
    const Ball& b = balls_[size_t(i)];
    const double g = b.kind == BallKind::Fireball ? 0.0 : scene_.physics.gravity;
    const double dt = scene_.physics.dt / std::max(1, scene_.physics.substeps);
    return 0.5 * glm::dot(b.velocity, b.velocity) + g * b.position.y - 0.5 * g * dt * b.velocity.y;
}

void World::writeTumblerInstances(std::vector<TumblerInstance>& out) const {
    out.resize(tumblers_.size());
    for (size_t i = 0; i < tumblers_.size(); ++i) {
        tumblers_[i].modelMatrix(out[i].model);
        for (int k = 0; k < 3; ++k) out[i].color[k] = float(tumblers_[i].color[k]);
        out[i].asleep = tumblers_[i].asleep ? 1u : 0u;
    }
}

void World::writeBallInstances(std::vector<BallInstance>& out) const {
    out.resize(balls_.size());
    for (size_t i = 0; i < balls_.size(); ++i) {
        const Ball& b = balls_[i];
        const Vec3 albedo = b.albedo(), emissive = b.emissiveColor();
        for (int k = 0; k < 3; ++k) {
            out[i].position[k] = float(b.position[k]);
            out[i].albedo[k] = float(albedo[k]);
            out[i].emissive[k] = float(emissive[k]);
        }
        out[i].radius = float(b.radius);
        out[i].kind = uint32_t(b.kind);
        out[i].strength = float(b.emissiveStrength());
    }
}

void World::writeParticleInstances(std::vector<ParticleInstance>& out) const {
    out.resize(particles_.size());
    for (size_t i = 0; i < particles_.size(); ++i) {
        const Particle& p = particles_[i];
        const Vec3 e = p.emission();
        for (int k = 0; k < 3; ++k) {
            out[i].position[k] = float(p.position[k]);
            out[i].emission[k] = float(e[k]);
        }
        out[i].radius = float(p.radius());
        out[i].kind = uint32_t(p.kind);
    }
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
