// tumbler_contacts.cpp — tumblers against the walls, the floor (toppled) and each other.
#include "internal.hpp"

namespace kiln::sim {

using namespace detail;

namespace {

// The course design's four-sphere test: each end sphere of one tumbler against the other's exact
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

bool World::collideTumblerWalls(int i) {
    bool pushed = false;
    // Both spheres against the four side walls: a horizontal push of O (the tumbler keeps
    // its orientation, so nothing else moves back in), then, if the touching point moves
    // into the wall, a rolling-constrained impulse that leaves it with −wall_decay times
    // its normal velocity.
    Tumbler& t = tumblers_[size_t(i)];
    const double radii[2] = {shape_.b(), shape_.t()};
    for (int axis : {0, 2}) {
        const Vec3 centres[2] = {t.position, t.upperCentre(shape_)};
        double push = 0.0;
        int touching = -1;
        for (int k = 0; k < 2; ++k) {
            const double limit = 1.0 - radii[k];
            if (centres[k][axis] > limit && limit - centres[k][axis] < push) push = limit - centres[k][axis], touching = k;
            if (centres[k][axis] < -limit && -limit - centres[k][axis] > push) push = -limit - centres[k][axis], touching = k;
        }
        if (touching < 0) continue;
        t.position[axis] += push;
        pushed = true;
        Vec3 n(0.0);  // into the box
        n[axis] = push < 0 ? -1.0 : 1.0;
        const Vec3 at = (touching == 0 ? t.position : t.upperCentre(shape_)) - n * radii[touching];
        const double vn = glm::dot(pointVelocity(i, at), n);
        const double k = rollingInverseMass(i, at, n);
        if (vn < 0.0 && k > 1e-12) applyRollingImpulse(i, at, (-(1.0 + scene_.physics.wallDecay) * vn / k) * n);
        wake(i);
    }
    return pushed;
}

void World::collideTumblerFloor(int i) {
    // The toppled regime. The lower sphere touches the floor while the tilt θ is below
    // 90° + α (where the side lies on the floor, axis·ŷ = (t − b)/y_t); beyond it the
    // upper sphere would go through. Roll back to that pose — a rotation about the
    // horizontal tilt axis through O with O shifted by the matching rolling distance, so
    // no slip creeps in — then give the upper sphere's lowest point a rolling-constrained
    // impulse that leaves it with −e_floor times its downward velocity.
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
    t.position += shape_.b() * angle * glm::cross(tiltAxis, Vec3(0, 1, 0));
    landOnSide(i);
}

void World::landOnSide(int i) {
    // The upper sphere's lowest point meets the floor: a rolling-constrained impulse there
    // leaves it with −e_floor times its downward velocity.
    Tumbler& t = tumblers_[size_t(i)];
    const Vec3 at = t.upperCentre(shape_) - Vec3(0, shape_.t(), 0), up(0, 1, 0);
    const double vn = pointVelocity(i, at).y, k = rollingInverseMass(i, at, up);
    if (vn < 0.0 && k > 1e-12) applyRollingImpulse(i, at, (-(1.0 + scene_.physics.restitution.tumblerFloor) * vn / k) * up);
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
        // The course design's approximation: each end sphere against the other's exact SDF.
        separation = fourSphereContact(*this, a, b, shape_, n, h);
        if (separation >= 0.0) return separation;
    }
    if (glm::length(n) < 0.5) {  // coincident: no direction; separate along x
        n = Vec3(ta.position.x <= tb.position.x ? 1.0 : -1.0, 0, 0);
        if (ta.position.x == tb.position.x) n = Vec3(a < b ? 1.0 : -1.0, 0, 0);
    }
    // Separate on the floor plane, half each (both stay on the floor); a contact normal
    // that is far from horizontal needs a longer horizontal push (up to 3×).
    Vec3 nh(n.x, 0.0, n.z);
    const double nhl = glm::length(nh);
    nh = nhl > 1e-9 ? nh / nhl : Vec3(1, 0, 0);
    const double depth = std::min(-separation / std::max(nhl, 1.0 / 3.0), 2.0 * shape_.b());
    ta.position -= nh * (0.5 * depth);
    tb.position += nh * (0.5 * depth);
    // Normal impulse with both tumblers' rolling-constrained responses: the relative
    // normal velocity at the contact becomes −e times what it was.
    const double vn = glm::dot(pointVelocity(b, h) - pointVelocity(a, h), n);
    const double k = rollingInverseMass(a, h, n) + rollingInverseMass(b, h, n);
    if (vn < 0.0 && k > 1e-12) {
        const double jn = -(1.0 + scene_.physics.restitution.tumblerTumbler) * vn / k;
        applyRollingImpulse(a, h, -jn * n);
        applyRollingImpulse(b, h, jn * n);
    }
    wake(a);
    wake(b);
    return separation;
}
}  // namespace kiln::sim
