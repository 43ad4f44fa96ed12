#include "scene/live_scene.hpp"

#include <algorithm>

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/type_ptr.hpp>

namespace kiln::scene {

namespace {

SceneLook lookOf(const sim::Scene& scene) {
    SceneLook look;
    look.left = glm::vec3(scene.box.left);
    look.right = glm::vec3(scene.box.right);
    look.other = glm::vec3(scene.box.other);
    look.woodLight = glm::vec3(scene.box.floorWood.light);
    look.woodDark = glm::vec3(scene.box.floorWood.dark);
    look.woodRingFrequency = float(scene.box.floorWood.ringFrequency);
    look.wallEmission = glm::vec3(scene.box.emission);
    look.closed = scene.box.closed;
    look.lampCentre = glm::vec3(scene.lamp.center);
    look.lampRadius = float(scene.lamp.radius);
    look.lampColor = glm::vec3(scene.lamp.color);
    look.lampIntensity = float(scene.lamp.intensity);
    look.tumblerB = float(scene.tumblerShape.b);
    look.tumblerT = float(scene.tumblerShape.t);
    look.tumblerAlpha = float(scene.tumblerShape.alpha);
    return look;
}

std::vector<BodyInstance> bodiesOf(const sim::World& world, int highlighted) {
    std::vector<BodyInstance> bodies;
    for (size_t i = 0; i < world.tumblers().size(); ++i) {
        const auto& t = world.tumblers()[i];
        BodyInstance b;
        b.category = kSceneTumblers;
        float m[16];
        t.modelMatrix(m);
        b.model = glm::make_mat4(m);
        b.albedo = glm::vec3(t.color);
        b.highlighted = int(i) == highlighted;
        bodies.push_back(b);
    }
    for (const auto& ball : world.balls()) {
        // The sim owns the look of a ball (burning marbles darken towards ash).
        BodyInstance b;
        b.category = ball.kind == sim::BallKind::Fireball ? kSceneFireballs : kSceneMarbles;
        b.model = glm::scale(glm::translate(glm::mat4(1.0f), glm::vec3(ball.position)), glm::vec3(float(ball.radius)));
        b.albedo = glm::vec3(ball.albedo());
        b.emissive = glm::vec3(ball.emissiveColor() * ball.emissiveStrength());
        bodies.push_back(b);
    }
    return bodies;
}

}  // namespace

bool LiveScene::load(const std::string& sceneFile, std::optional<uint64_t> seed, std::string& error) {
    sim::Scene scene;
    if (!sim::loadScene(sceneFile, scene, error)) return false;
    if (seed) scene.physics.seed = *seed;
    sim_.reset(scene);
    file_ = sceneFile;
    look_ = lookOf(scene);
    ++generation_;
    return true;
}

void LiveScene::writeTo(SceneRenderer& renderer, int highlighted) {
    if (sentGeneration_ != generation_) {
        renderer.setLook(look_);
        sentGeneration_ = generation_;
        sentBodies_ = sentParticles_ = sentFireballs_ = ~0ull;
    }
    if (sim_.bodiesVersion() != sentBodies_ || highlighted != sentHighlight_) {
        renderer.setBodies(bodiesOf(sim_, highlighted));
        sentBodies_ = sim_.bodiesVersion();
        sentHighlight_ = highlighted;
    }
    if (sim_.particlesVersion() != sentParticles_ || sim_.bodiesVersion() != sentFireballs_) {
        // A particle wholly inside a fireball (they are born within its radius) is hidden
        // by its opaque sphere: it shows nothing and lights nothing, so it is not drawn,
        // voxelized or path-traced. Left in, it hid the lamp a second time behind the
        // fireball's own disc (voxelize's fire cover) and cost the cover's test 3 ms at 50
        // fireballs on llvmpipe where this loop costs the CPU about 0.1 (0.36 with a square
        // root a pair: |p - c| + r <= R is |p - c|² <= (R - r)² with R >= r). Only the
        // fireballs within the largest radius of the particle along x can hide it: sorted
        // by x, those are a range (4 000 particles against 50 fireballs, every pair tested,
        // took 0.3 ms a frame).
        std::vector<glm::dvec4> fireballs;  // xyz centre, w radius
        double largest = 0.0;
        for (const auto& b : sim_.balls())
            if (b.kind == sim::BallKind::Fireball) {
                fireballs.emplace_back(b.position, b.radius);
                largest = std::max(largest, b.radius);
            }
        std::sort(fireballs.begin(), fireballs.end(),
                  [](const glm::dvec4& a, const glm::dvec4& b) { return a.x < b.x; });
        std::vector<ParticleInstance> particles;
        particles.reserve(sim_.particles().size());
        for (const auto& p : sim_.particles()) {
            const double r = p.radius();
            bool hidden = false;
            auto f = std::lower_bound(fireballs.begin(), fireballs.end(), p.position.x - largest,
                                      [](const glm::dvec4& b, double x) { return b.x < x; });
            for (; !hidden && f != fireballs.end() && f->x <= p.position.x + largest; ++f) {
                const glm::dvec3 d = p.position - glm::dvec3(*f);
                hidden = f->w >= r && glm::dot(d, d) <= (f->w - r) * (f->w - r);
            }
            if (!hidden) particles.push_back({glm::vec3(p.position), float(r), glm::vec3(p.emission())});
        }
        renderer.setParticles(particles);
        sentParticles_ = sim_.particlesVersion();
        sentFireballs_ = sim_.bodiesVersion();
    }
}

}  // namespace kiln::scene
