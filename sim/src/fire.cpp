// fire.cpp — fire, sparks and ash: ignition, the particle pool, particle motion.
#include "internal.hpp"

namespace kiln::sim {

using namespace detail;

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
}  // namespace kiln::sim
