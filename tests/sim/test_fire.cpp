// Fire: ignition, burning, ash; particle rates, pooling and caps; version counters.
#include <catch2/catch.hpp>

#include "kiln/sim/world.hpp"

using namespace kiln::sim;

namespace {
Scene emptyScene() {
    Scene s;
    s.physics.friction = 0.0;
    return s;
}
int count(const World& w, ParticleKind kind) {
    int n = 0;
    for (auto& p : w.particles()) n += p.kind == kind;
    return n;
}
}  // namespace

TEST_CASE("a fireball sets a marble burning, which crumbles to glowing, cooling ash", "[sim][fire]") {
    Scene s = emptyScene();
    s.marbles.push_back({{0.0, 0.0, 0.5}, {0.0, 0.0, 0.0}, 0.05, {0.9, 0.9, 0.9}});
    s.fireballs.push_back({{-0.4, 0.0, 0.5}, {4.0, 0.0, 0.0}, 0.06, {1.0, 0.5, 0.1}});
    World w(s);
    int frame = 0;
    while (w.balls()[0].kind == BallKind::Marble && frame < 60) w.step(), ++frame;
    REQUIRE(w.balls()[0].kind == BallKind::Burning);
    CHECK(count(w, ParticleKind::Spark) > 0);          // the hit threw sparks
    CHECK(w.balls()[0].emissiveStrength() > 0.0);       // it glows
    CHECK(glm::length(w.balls()[0].albedo()) <= glm::length(Vec3(0.9)));
    // After kBurnDuration it is gone and ash is left.
    for (int i = 0; i < int(kBurnDuration / s.physics.dt) + 10; ++i) w.step();
    REQUIRE(w.balls().size() == 1);
    CHECK(w.balls()[0].kind == BallKind::Fireball);
    CHECK(count(w, ParticleKind::Ash) > 20);
    // Ash glows while large and turns black once it has shrunk (cooling).
    Particle ash;
    ash.kind = ParticleKind::Ash;
    ash.maxLife = 1.0;
    ash.life = 0.95;
    const Vec3 hot = ash.emission();
    ash.life = 0.2;
    CHECK(glm::length(hot) > 1.0);
    CHECK(ash.emission() == Vec3(0.0));
    CHECK(ash.radius() < 0.012);
}

TEST_CASE("fire: 400 particles per second per fireball, each living 0.45 s", "[sim][fire]") {
    Scene s = emptyScene();
    s.fireballs.push_back({{0.5, 0.0, 0.5}, {0.0, 0.0, 0.0}, 0.06, {1.0, 0.5, 0.1}});  // at rest: no sparks
    World w(s);
    for (int i = 0; i < 480; ++i) w.step();
    // Steady state: 400/s × 0.45 s = 180 alive; ±2 for the frame quantisation of birth
    // and death (1.67 per frame at dt = 1/240).
    CHECK(count(w, ParticleKind::Fire) >= 178);
    CHECK(count(w, ParticleKind::Fire) <= 182);
    CHECK(count(w, ParticleKind::Spark) == 0);
    // Spawned inside the fireball (and then drifting up at most 1.2 m/s × 0.45 s).
    for (auto& p : w.particles()) CHECK(glm::length(p.position - Vec3(0.5, 0.0, 0.5)) < 0.06 + 0.6);
}

TEST_CASE("particles stay within the pool: bounded count, no reallocation", "[sim][fire]") {
    Scene s = emptyScene();
    World w(s);
    for (int i = 0; i < 40; ++i) w.spawnRandom(BallKind::Fireball);
    for (int i = 0; i < 20; ++i) w.spawnRandom(BallKind::Marble);
    const Particle* pool = w.particles().data();
    size_t most = 0;
    for (int i = 0; i < 720; ++i) {
        w.step();
        most = std::max(most, w.particles().size());
        REQUIRE(w.particles().size() <= World::kMaxParticles);
        REQUIRE(w.particles().capacity() == World::kMaxParticles);
    }
    CHECK(w.particles().data() == pool);  // the same storage throughout
    CHECK(most == World::kMaxParticles);   // 40 fireballs want 7200 alive: the cap held
    CHECK(w.allFinite());
}

TEST_CASE("particlesVersion bumps only when the particle set changes", "[sim][fire]") {
    Scene s = emptyScene();
    s.marbles.push_back({{0.5, 0.0, 0.5}, {0.0, 0.0, 0.0}, 0.05, {1, 1, 1}});
    World w(s);
    const uint64_t v = w.particlesVersion(), b = w.bodiesVersion();
    for (int i = 0; i < 10; ++i) w.step();
    CHECK(w.particlesVersion() == v);  // no fire, no particles: nothing to upload
    CHECK(w.bodiesVersion() > b);      // the marble falls
    w.spawnFireball(Vec3(-0.5, 0.0, -0.5), Vec3(0.0));
    w.step();
    CHECK(w.particlesVersion() > v);
}
