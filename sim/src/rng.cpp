// rng.cpp — PCG32 (O'Neill) and the two sphere samplers built on it.
#include "internal.hpp"

namespace kiln::sim {

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
}  // namespace kiln::sim
