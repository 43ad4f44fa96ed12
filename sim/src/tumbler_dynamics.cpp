// tumbler_dynamics.cpp — one tumbler sub-step: gravity, the restoring impulse (seed mode),
// rolling without slipping, friction, integration and sleep.
#include "internal.hpp"

namespace kiln::sim {

using namespace detail;

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
}  // namespace kiln::sim
