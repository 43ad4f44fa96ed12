// diagnostics.cpp — the state hash (FNV-1a) and the invariants tests and kiln-sim check.
#include "internal.hpp"

namespace kiln::sim {

using namespace detail;

namespace {

// FNV-1a, 64 bit: the sim's only hash. Fields are fed one by one (never whole structs,
// whose padding bytes are indeterminate).
struct Fnv1a {
    uint64_t h = 1469598103934665603ull;
    void bytes(const void* data, size_t n) {
        const auto* p = static_cast<const unsigned char*>(data);
        for (size_t i = 0; i < n; ++i) h = (h ^ p[i]) * 1099511628211ull;
    }
    void add(double v) { bytes(&v, sizeof v); }
    void add(uint64_t v) { bytes(&v, sizeof v); }
    void add(int v) { add(uint64_t(int64_t(v))); }
    void add(bool v) { add(uint64_t(v ? 1 : 0)); }
    void add(const Vec3& v) { add(v.x), add(v.y), add(v.z); }
    void add(const Quat& q) { add(q.w), add(q.x), add(q.y), add(q.z); }
};

}  // namespace

uint64_t World::stateHash() const {
    // Everything step() reads or writes: a difference anywhere in the state changes it.
    Fnv1a f;
    f.add(uint64_t(tumblers_.size()));
    for (auto& t : tumblers_) {
        f.add(t.position), f.add(t.orientation), f.add(t.velocity), f.add(t.angularVelocity);
        f.add(t.color), f.add(t.asleep), f.add(t.restTime);
    }
    f.add(uint64_t(balls_.size()));
    for (auto& b : balls_) {
        f.add(b.position), f.add(b.velocity), f.add(b.angularVelocity), f.add(b.radius);
        f.add(uint64_t(b.kind)), f.add(b.color), f.add(b.burnTime), f.add(b.fireOwed);
    }
    f.add(uint64_t(particles_.size()));
    for (auto& p : particles_) {
        f.add(p.position), f.add(p.velocity), f.add(p.life), f.add(p.maxLife), f.add(p.size);
        f.add(uint64_t(p.kind));
    }
    f.add(rng_.state()), f.add(rng_.stream());
    f.add(time_), f.add(steps_), f.add(removedBallEnergy_), f.add(substepDt_);
    f.add(drag_.tumbler), f.add(uint64_t(drag_.mode)), f.add(drag_.planeY), f.add(drag_.offset);
    return f.h;
}

double World::ballEnergy(int i) const {
    const Ball& b = balls_[size_t(i)];
    const double g = b.kind == BallKind::Fireball ? 0.0 : scene_.physics.gravity;
    const double dt = substepDt_;
    return 0.5 * glm::dot(b.velocity, b.velocity) + g * b.position.y - 0.5 * g * dt * b.velocity.y;
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

double World::deepestTumblerOverlap() const {
    double worst = 0.0;
    for (size_t a = 0; a < tumblers_.size(); ++a)
        for (size_t b = a + 1; b < tumblers_.size(); ++b) {
            const Tumbler& ta = tumblers_[a];
            const Tumbler& tb = tumblers_[b];
            worst = std::min(worst, roundConeSeparation(ta.position, ta.upperCentre(shape_), shape_.b(), shape_.t(),
                                                        tb.position, tb.upperCentre(shape_), shape_.b(), shape_.t())
                                        .distance);
        }
    return worst;
}
}  // namespace kiln::sim
