// picking.cpp — mouse picking (sphere tracing) and the translate / rotate drags.
#include "internal.hpp"

namespace kiln::sim {

using namespace detail;

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
    // docs/physics.md §4: a hit below the centre of mass translates, above rotates (the course design's
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
}  // namespace kiln::sim
