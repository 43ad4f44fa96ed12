// tumbler_contacts.cpp — tumblers against the walls, the floor (toppled) and each other.
#include "internal.hpp"

namespace kiln::sim {

using namespace detail;

namespace {

// The seed's four-sphere test: each end sphere of one tumbler against the other's exact
// SDF; the contact point and normal (A → B) are averaged over the spheres that touch.
// Returns the smallest sphere separation (negative: overlap).
double fourSphereContact(const World& w, int a, int b, const RoundCone& shape, Vec3& n, Vec3& h) {
    const Tumbler& ta = w.tumblers()[size_t(a)];
    const Tumbler& tb = w.tumblers()[size_t(b)];
    int hits = 0;
    double separation = std::numeric_limits<double>::infinity();
    auto test = [&](int other, const Vec3& centre, double radius, double sign) {
        const double d = w.tumblerSdf(other, centre);
        separation = std::min(separation, d - radius);
        if (d - radius >= 0.0) return;
        const Vec3 g = w.tumblerNormal(other, centre);
        n += sign * g;  // sign makes it point from A to B
        h += centre - g * d;
        ++hits;
    };
    test(b, ta.position, shape.b(), -1.0);
    test(b, ta.upperCentre(shape), shape.t(), -1.0);
    test(a, tb.position, shape.b(), 1.0);
    test(a, tb.upperCentre(shape), shape.t(), 1.0);
    if (hits == 0) return separation;
    h /= double(hits);
    const double nl = glm::length(n);
    n = nl > 1e-9 ? n / nl : Vec3(0.0);
    return separation;
}

}  // namespace

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
        // The seed's approximation: each end sphere against the other's exact SDF.
        separation = fourSphereContact(*this, a, b, shape_, n, h);
        if (separation >= 0.0) return separation;
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
}  // namespace kiln::sim
