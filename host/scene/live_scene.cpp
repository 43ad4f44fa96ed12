#include "scene/live_scene.hpp"

#include <algorithm>

#include <filesystem>

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/type_ptr.hpp>

#include "kiln/log.hpp"

namespace kiln::scene {

namespace {

SceneLook lookOf(const sim::Scene& scene) {
    SceneLook look;
    look.left = glm::vec3(scene.box.left);
    look.right = glm::vec3(scene.box.right);
    look.other = glm::vec3(scene.box.other);
    look.ringsLight = glm::vec3(scene.box.floorWood.light);
    look.ringsDark = glm::vec3(scene.box.floorWood.dark);
    look.woodRingFrequency = float(scene.box.floorWood.ringFrequency);
    look.wallEmission = glm::vec3(scene.box.emission);
    look.closed = scene.box.closed;
    look.walls = scene.box.walls;
    look.lampCentre = glm::vec3(scene.lamp.center);
    look.lampRadius = float(scene.lamp.radius);
    look.lampColor = glm::vec3(scene.lamp.color);
    look.lamp = scene.box.lamp;
    look.lampIntensity = scene.box.lamp ? float(scene.lamp.intensity) : 0.0f;
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
        b.category = kSceneRoundCones;
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
        b.category = ball.kind == sim::BallKind::Fireball ? kSceneGlowingSpheres : kSceneSpheres;
        b.model = glm::scale(glm::translate(glm::mat4(1.0f), glm::vec3(ball.position)), glm::vec3(float(ball.radius)));
        b.albedo = glm::vec3(ball.albedo());
        b.emissive = glm::vec3(ball.emissiveColor() * ball.emissiveStrength());
        bodies.push_back(b);
    }
    return bodies;
}

bool isGltfFile(const std::string& path) {
    const std::string ext = std::filesystem::path(path).extension().string();
    return ext == ".gltf" || ext == ".glb";
}

// Where a model spec puts the model: translate × rotate (x, then y, then z) × scale,
// after the fit when it asks for one: in the box, its bounds on the floor, centred,
// within x, z ∈ [-0.8, 0.8] and 1.4 high, under the lamp; without walls, centred in
// [-0.9, 0.9]³.
glm::mat4 placementOf(const sim::Scene::ModelSpec& spec, const model::Model& m, bool walls) {
    glm::mat4 fit(1.0f);
    if (spec.fit && !walls) {
        const glm::vec3 extent = glm::max(m.boundsMax - m.boundsMin, glm::vec3(1e-6f));
        const float s = 1.8f / std::max({extent.x, extent.y, extent.z});
        fit = glm::scale(glm::mat4(1.0f), glm::vec3(s)) * glm::translate(glm::mat4(1.0f), -0.5f * (m.boundsMin + m.boundsMax));
    } else if (spec.fit) {
        const glm::vec3 extent = glm::max(m.boundsMax - m.boundsMin, glm::vec3(1e-6f));
        const float s = std::min({1.6f / extent.x, 1.4f / extent.y, 1.6f / extent.z});
        const glm::vec3 base(0.5f * (m.boundsMin.x + m.boundsMax.x), m.boundsMin.y, 0.5f * (m.boundsMin.z + m.boundsMax.z));
        fit = glm::translate(glm::mat4(1.0f), glm::vec3(0.0f, -1.0f, 0.0f)) * glm::scale(glm::mat4(1.0f), glm::vec3(s)) *
              glm::translate(glm::mat4(1.0f), -base);
    }
    // A fitted model turns and scales about where the fit put it (the middle of its base
    // on the floor, or the volume's centre), so it stays standing there.
    const glm::vec3 pivot = spec.fit && walls ? glm::vec3(0.0f, -1.0f, 0.0f) : glm::vec3(0.0f);
    const glm::vec3 r = glm::radians(glm::vec3(spec.rotationDeg));
    glm::mat4 t = glm::translate(glm::mat4(1.0f), glm::vec3(spec.position) + pivot);
    t = glm::rotate(t, r.z, glm::vec3(0, 0, 1));
    t = glm::rotate(t, r.y, glm::vec3(0, 1, 0));
    t = glm::rotate(t, r.x, glm::vec3(1, 0, 0));
    return t * glm::scale(glm::mat4(1.0f), glm::vec3(float(spec.scale))) * glm::translate(glm::mat4(1.0f), -pivot) * fit;
}

}  // namespace

bool LiveScene::loadModels(const sim::Scene& scene, const std::string& sceneFile, std::vector<PlacedModel>& out,
                           std::string& error) const {
    namespace fs = std::filesystem;
    out.clear();
    for (size_t i = 0; i < scene.models.size(); ++i) {
        const sim::Scene::ModelSpec& spec = scene.models[i];
        fs::path file = spec.file;
        if (file.is_relative() && !isGltfFile(sceneFile)) file = fs::path(sceneFile).parent_path() / file;
        auto m = std::make_shared<model::Model>();
        std::string why;
        if (!model::loadGltf(file.string(), *m, why)) {
            error = isGltfFile(sceneFile) ? why : sceneFile + ": models[" + std::to_string(i) + "].file: " + why;
            return false;
        }
        for (const std::string& w : m->warnings) log::warn(file.string(), ": ", w);
        out.push_back({m, placementOf(spec, *m, scene.box.walls)});
    }
    return true;
}

bool LiveScene::load(const std::string& sceneFile, std::optional<uint64_t> seed, std::string& error) {
    sim::Scene scene;
    if (isGltfFile(sceneFile)) {
        // A model alone: the box and its lamp as the default scene has them, no bodies.
        scene.models.push_back({sceneFile, glm::dvec3(0.0), 1.0, glm::dvec3(0.0), true});
    } else if (!sim::loadScene(sceneFile, scene, error)) {
        return false;
    }
    std::vector<PlacedModel> models;
    if (!loadModels(scene, sceneFile, models, error)) return false;
    // A model with lights of its own is shown alone, lit by them, at its own size (the
    // voxel volume follows it); one without stands in the box under its lamp, fitted.
    if (isGltfFile(sceneFile) && !models[0].model->lights.empty()) {
        scene.box.walls = false;
        scene.box.lamp = false;
        scene.models[0].fit = false;
        models[0].placement = placementOf(scene.models[0], *models[0].model, false);
    }
    if (seed) scene.physics.seed = *seed;
    sim_.reset(scene);
    spec_ = scene;
    placeModels(std::move(models));
    file_ = sceneFile;
    look_ = lookOf(scene);
    ++generation_;
    return true;
}

bool LiveScene::reloadModels(std::string& error) {
    std::vector<PlacedModel> models;
    if (!loadModels(spec_, file_, models, error)) return false;
    placeModels(std::move(models));
    return true;
}

void LiveScene::placeModels(std::vector<PlacedModel> models) {
    models_ = std::move(models);
    ++modelsVersion_;
    lights_.clear();
    // The box's, and the models'.
    bool any = spec_.box.walls;
    boundsMin_ = glm::vec3(any ? -1.0f : 0.0f), boundsMax_ = glm::vec3(any ? 1.0f : 0.0f);
    for (const PlacedModel& p : models_) {
        const glm::mat4& m = p.placement;
        const float scale = std::cbrt(std::abs(glm::determinant(glm::mat3(m))));
        for (model::Light l : p.model->lights) {
            l.position = glm::vec3(m * glm::vec4(l.position, 1.0f));
            l.direction = glm::normalize(glm::mat3(m) * l.direction);
            if (l.type != model::Light::Type::Directional) l.intensity *= scale * scale, l.range *= scale;
            lights_.push_back(l);
        }
        for (int c = 0; c < 8; ++c) {
            const glm::vec3 corner((c & 1) ? p.model->boundsMax.x : p.model->boundsMin.x,
                                   (c & 2) ? p.model->boundsMax.y : p.model->boundsMin.y,
                                   (c & 4) ? p.model->boundsMax.z : p.model->boundsMin.z);
            const glm::vec3 w = glm::vec3(m * glm::vec4(corner, 1.0f));
            boundsMin_ = any ? glm::min(boundsMin_, w) : w, boundsMax_ = any ? glm::max(boundsMax_, w) : w;
            any = true;
        }
    }
    if (lights_.size() > size_t(kMaxPunctualLights))
        log::warn(file_, ": ", lights_.size(), " punctual lights; the first ", kMaxPunctualLights, " are drawn");
}

bool LiveScene::modelCamera(glm::vec3& eye, glm::vec3& forward, float& fovY) const {
    if (!isGltfFile(file_) || models_.empty() || models_[0].model->cameras.empty()) return false;
    const model::Camera& c = models_[0].model->cameras[0];
    const glm::mat4 world = models_[0].placement * c.transform;
    eye = glm::vec3(world[3]);
    forward = glm::normalize(-glm::vec3(world[2]));
    fovY = c.yfov;
    return true;
}

std::vector<std::string> LiveScene::modelFiles() const {
    std::vector<std::string> files;
    for (const PlacedModel& p : models_) files.insert(files.end(), p.model->files.begin(), p.model->files.end());
    return files;
}

void LiveScene::writeTo(SceneRenderer& renderer, int highlighted) {
    if (sentGeneration_ != generation_) {
        renderer.setLook(look_);
        sentGeneration_ = generation_;
        sentBodies_ = sentParticles_ = sentFireballs_ = ~0ull;
    }
    if (sentModels_ != modelsVersion_) {
        std::string error;
        if (!renderer.setModels(models_, error)) log::error(file_, ": ", error, " (the last models stay)");
        sentModels_ = modelsVersion_;
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
