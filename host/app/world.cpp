#include "app/world.hpp"

#include "app/cli.hpp"

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/type_ptr.hpp>

namespace kiln::app {

bool World::load(const std::string& sceneFile, uint64_t seed, std::string& error) {
    sim::Scene scene;
    if (!sim::loadScene(sceneFile, scene, error)) return false;
    if (seed != kSceneSeed) scene.physics.seed = seed;
    sim_.reset(scene);
    file_ = sceneFile;
    box_.left = glm::vec3(scene.box.left);
    box_.right = glm::vec3(scene.box.right);
    box_.other = glm::vec3(scene.box.other);
    box_.lampCentre = glm::vec3(scene.lamp.center);
    box_.lampRadius = float(scene.lamp.radius);
    box_.lampColor = glm::vec3(scene.lamp.color);
    box_.lampIntensity = float(scene.lamp.intensity);
    shape_ = {float(scene.tumblerShape.b), float(scene.tumblerShape.t), float(scene.tumblerShape.alpha)};
    ++generation_;
    return true;
}

void World::sync(SceneRenderer& scene, uint64_t versions[6], int highlighted) {
    if (seenGeneration_ != generation_) {
        scene.setBox(box_);
        ++versions[sceneCategoryIndex(kSceneStatic)];
        ++versions[sceneCategoryIndex(kSceneLight)];
        seenGeneration_ = generation_;
        seenBodies_ = seenParticles_ = ~0ull;
    }
    if (sim_.bodiesVersion() != seenBodies_ || highlighted != seenHighlight_) {
        std::vector<BodyInstance> bodies;
        for (size_t i = 0; i < sim_.tumblers().size(); ++i) {
            const auto& t = sim_.tumblers()[i];
            BodyInstance b;
            b.category = kDrawTumblers;
            float m[16];
            t.modelMatrix(m);
            b.model = glm::make_mat4(m);
            b.albedo = glm::vec3(t.color);
            b.highlighted = int(i) == highlighted;
            bodies.push_back(b);
        }
        for (const auto& ball : sim_.balls()) {
            // The sim owns the look of a ball (burning marbles darken towards ash).
            BodyInstance b;
            b.category = ball.kind == sim::BallKind::Fireball ? kDrawFireballs : kDrawMarbles;
            b.model = glm::scale(glm::translate(glm::mat4(1.0f), glm::vec3(ball.position)), glm::vec3(float(ball.radius)));
            b.albedo = glm::vec3(ball.albedo());
            b.emissive = glm::vec3(ball.emissiveColor() * ball.emissiveStrength());
            bodies.push_back(b);
        }
        scene.setBodies(bodies);
        ++versions[sceneCategoryIndex(kSceneBodies)];
        seenBodies_ = sim_.bodiesVersion();
        seenHighlight_ = highlighted;
    }
    if (sim_.particlesVersion() != seenParticles_) {
        std::vector<ParticleInstance> particles;
        particles.reserve(sim_.particles().size());
        for (const auto& p : sim_.particles())
            particles.push_back({glm::vec3(p.position), float(p.radius()), glm::vec3(p.emission())});
        scene.setParticles(particles);
        ++versions[sceneCategoryIndex(kSceneParticles)];
        seenParticles_ = sim_.particlesVersion();
    }
}

}  // namespace kiln::app
