// tumbler_dynamics.cpp — one tumbler sub-step.
//
// Accurate mode: exact rolling without slipping on the floor (sim/README.md, "Exact
// rolling", has the derivation). State (O_x, O_z, q, ω); O_y = −1 + b and v_O = b·ω × ŷ
// follow from the constraint. With P = O − b·ŷ the floor contact, s = R·c the centre of
// mass G relative to O and r = G − P = b·ŷ + s, Newton–Euler with the contact force
// eliminated gives
//     A·ω̇ = −ω × I_G·ω − m·r × (ω × (ω × s)) − m·g·r × ŷ,     A = I_G + m(|r|²𝟙 − r·rᵀ),
// where the middle term is the acceleration of G that the moving contact point adds
// (ṙ = ω × s, not ω × r: P slides along the lower sphere). Integrated with classical
// RK4 on (O, q, ω), q renormalised after each step.
//
// Course mode keeps the course design's model: centre of mass at O, the restoring impulse −Δt·d at
// one unit above O, and rolling imposed as a velocity impulse each sub-step
// (semi-implicit Euler). Both modes then apply docs/physics.md §3's friction and sleep.
#include "internal.hpp"

namespace kiln::sim {

using namespace detail;

namespace {

struct RollState {
    Vec3 o;  // the lower-sphere centre O
    Quat q;
    Vec3 w;  // angular velocity, world frame
};

struct RollBody {
    double m, g, b;
    Vec3 com;       // centre of mass in the local frame (0, −h, 0)
    Vec3 inertia;   // principal inertia about G (local axes)

    RollState derivative(const RollState& s) const {
        const Mat3 R = glm::mat3_cast(glm::normalize(s.q));
        const Vec3 sG = R * com, r = Vec3(0, b, 0) + sG;
        const Mat3 IG = R * Mat3(inertia.x, 0, 0, 0, inertia.y, 0, 0, 0, inertia.z) * glm::transpose(R);
        const Mat3 A = IG + m * (glm::dot(r, r) * Mat3(1.0) - glm::outerProduct(r, r));
        const Vec3& w = s.w;
        const Vec3 rhs = -glm::cross(w, IG * w) - m * glm::cross(r, glm::cross(w, glm::cross(w, sG))) -
                         m * g * glm::cross(r, Vec3(0, 1, 0));
        RollState d;
        d.o = b * Vec3(-w.z, 0.0, w.x);                 // v_O = b·ω × ŷ
        d.q = 0.5 * (Quat(0.0, w.x, w.y, w.z) * s.q);   // q̇ = ½(0, ω)·q
        d.w = glm::inverse(A) * rhs;
        return d;
    }
};

RollState axpy(const RollState& s, double h, const RollState& d) {
    return {s.o + h * d.o, s.q + h * d.q, s.w + h * d.w};
}

RollState rk4(const RollBody& body, const RollState& s, double dt) {
    const RollState k1 = body.derivative(s);
    const RollState k2 = body.derivative(axpy(s, 0.5 * dt, k1));
    const RollState k3 = body.derivative(axpy(s, 0.5 * dt, k2));
    const RollState k4 = body.derivative(axpy(s, dt, k3));
    RollState out;
    out.o = s.o + (dt / 6.0) * (k1.o + 2.0 * k2.o + 2.0 * k3.o + k4.o);
    out.q = glm::normalize(s.q + (dt / 6.0) * (k1.q + 2.0 * k2.q + 2.0 * k3.q + k4.q));
    out.w = s.w + (dt / 6.0) * (k1.w + 2.0 * k2.w + 2.0 * k3.w + k4.w);
    return out;
}

}  // namespace

void World::stepTumbler(int i, double dt) {
    Tumbler& t = tumblers_[size_t(i)];
    if (t.asleep || drag_.tumbler == i) return;
    if (scene_.physics.tumblerMode == TumblerMode::Course) stepTumblerCourse(i, dt);
    else stepTumblerRolling(i, dt);
    applyFriction(t, dt);
    t.velocity = shape_.b() * Vec3(-t.angularVelocity.z, 0.0, t.angularVelocity.x);
    updateSleep(t, dt);
    bodiesMoved_ = true;
}

void World::stepTumblerRolling(int i, double dt) {
    // A step that would tilt the tumbler past lying on its side (axis·ŷ below
    // (t − b)/y_t, the upper sphere in the floor) is split at the moment it gets there
    // (bisection on the step length, each trial a fresh RK4 from the step's start): the
    // floor's impulse acts at that pose, then the rest of the step runs. So the landing
    // neither loses nor gains energy beyond the restitution's, whatever the Δt.
    Tumbler& t = tumblers_[size_t(i)];
    const RollBody body{tumblerMass(), scene_.physics.gravity, shape_.b(), comLocal_, inertiaCom_};
    const double cosLying = (shape_.t() - shape_.b()) / shape_.upperCentre();
    auto lying = [&](const RollState& st) { return (st.q * Vec3(0, 1, 0)).y < cosLying; };
    RollState start{t.position, t.orientation, t.angularVelocity};
    double left = dt;
    for (int event = 0; event < 4 && left > 0.0; ++event) {
        RollState next = rk4(body, start, left);
        if (!lying(next) || lying(start)) {
            start = next;
            left = 0.0;
            break;
        }
        double lo = 0.0, hi = left;  // lying(rk4(lo)) false, lying(rk4(hi)) true
        for (int it = 0; it < 40; ++it) {
            const double mid = 0.5 * (lo + hi);
            (lying(rk4(body, start, mid)) ? hi : lo) = mid;
        }
        start = rk4(body, start, lo);
        left -= lo;
        t.position = Vec3(start.o.x, -1.0 + shape_.b(), start.o.z), t.orientation = start.q;
        t.angularVelocity = start.w;
        landOnSide(i);
        start = {t.position, t.orientation, t.angularVelocity};
        if (left < 1e-12 * dt) left = 0.0;
    }
    if (left > 0.0) start = rk4(body, start, left);  // resting on its side: collideTumblerFloor settles it
    t.position = Vec3(start.o.x, -1.0 + shape_.b(), start.o.z);
    t.orientation = start.q;
    t.angularVelocity = start.w;
}

void World::stepTumblerCourse(int i, double dt) {
    Tumbler& t = tumblers_[size_t(i)];
    const double m = tumblerMass(), b = shape_.b();
    Vec3 g = t.position + t.rotation() * comLocal_;
    Vec3 vG = t.velocity + glm::cross(t.angularVelocity, g - t.position);
    Vec3& w = t.angularVelocity;
    const Mat3 invI = inverseInertiaWorld(i);
    vG.y -= scene_.physics.gravity * dt;
    // The course design's restoring impulse −Δt·d at one unit above O.
    const Vec3 j = -dt * t.axis(), at = t.position + Vec3(0, 1, 0);
    vG += j / m;
    w += invI * glm::cross(at - g, j);
    // Rolling contact at the lowest point of the lower sphere: the contact point's
    // velocity goes to zero (no slip, no penetration) through one 3D impulse j with
    // K·j = −v_c, K = (1/m)𝟙 − [r]× I⁻¹ [r]×. Only a pushing floor acts (j_y ≥ 0).
    const Vec3 rc = Vec3(t.position.x, -1.0, t.position.z) - g;
    const Mat3 K = Mat3(1.0 / m) - skew(rc) * invI * skew(rc);
    const Vec3 jc = solveImpulse(K, -(vG + glm::cross(w, rc)));
    if (jc.y >= 0.0) {
        vG += jc / m;
        w += invI * glm::cross(rc, jc);
    }
    // Semi-implicit Euler of the centre of mass and the orientation (first order).
    g += vG * dt;
    const Quat dq(0.0, w.x, w.y, w.z);
    t.orientation = glm::normalize(t.orientation + (dt * 0.5) * (dq * t.orientation));
    t.position = g - t.rotation() * comLocal_;
    t.position.y = -1.0 + b;  // stays on the floor (docs/physics.md §3)
}

void World::applyFriction(Tumbler& t, double dt) const {
    // docs/physics.md §3: friction damps rocking and rolling, |ω| falls by μg·Δt/b per sub-step.
    const auto& ph = scene_.physics;
    if (ph.friction <= 0) return;
    Vec3& w = t.angularVelocity;
    const double wl = glm::length(w), dw = ph.friction * ph.gravity * dt / shape_.b();
    w = wl > dw ? w * ((wl - dw) / wl) : Vec3(0.0);
}

void World::updateSleep(Tumbler& t, double dt) {
    // Sleep after 0.5 s below the thresholds: upright at rest, or lying on the floor.
    // A rocking tumbler passes through ω ≈ 0 only for an instant, so the continuous
    // 0.5 s keeps it awake.
    if (glm::length(t.velocity) < 2e-3 && glm::length(t.angularVelocity) < 2e-2) {
        t.restTime += dt;
        if (t.restTime > 0.5) {
            t.asleep = true;
            t.velocity = t.angularVelocity = Vec3(0.0);
        }
    } else {
        t.restTime = 0.0;
    }
}

}  // namespace kiln::sim
