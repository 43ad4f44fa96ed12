// The reference over glTF triangles (the host's BVH, shaders/common/ray_meshes.glsl):
// a white furnace made of triangles, the box's walls as triangles against the same walls
// as exact planes, and a punctual light's light and shadow against the closed form.
#include <catch2/catch.hpp>

#include <algorithm>
#include <array>
#include <cmath>

#include <nlohmann/json.hpp>

#include "gi/embree_tracer.hpp"
#include "gi/quads_gltf.hpp"
#include "gi/rig.hpp"
#include "model/model.hpp"

using namespace kiln;
using namespace kiln::test;

namespace {

constexpr float kPi = 3.14159265358979f;

FloatImage renderReference(Rig& rig, int samples, int frames, int seed, const char* output = "radiance") {
    rig.load(pipeline(std::string("reference.") + output,
                      R"({"id": "reference", "module": "reference", "params": {"samples_per_frame": )" +
                          std::to_string(samples / frames) + R"(, "seed": )" + std::to_string(seed) +
                          R"(, "max_bounces": 64, "budget_ms": 0}})"),
             {"reference.radiance", "reference.direct"});
    for (int f = 0; f < frames; ++f) rig.app.frame();
    rig.checkNoErrors();
    FloatImage img = rig.image("reference", output);
    REQUIRE(img.at(0, 0)[3] == float(samples));
    return img;
}

// The median of |a − b| over every pixel and channel: the size of the noise between two
// independent estimates, robust to the rare bright path (an RMSE of these images moves
// by 2× from one pair of seeds to another).
double medianDifference(const FloatImage& a, const FloatImage& b) {
    std::vector<double> d;
    for (int y = 0; y < a.height; ++y)
        for (int x = 0; x < a.width; ++x)
            for (int c = 0; c < 3; ++c) d.push_back(std::abs(double(a.at(x, y)[c]) - b.at(x, y)[c]));
    std::nth_element(d.begin(), d.begin() + std::ptrdiff_t(d.size() / 2), d.end());
    return d[d.size() / 2];
}

double mean(const FloatImage& a) {
    double sum = 0.0;
    for (int y = 0; y < a.height; ++y)
        for (int x = 0; x < a.width; ++x)
            for (int c = 0; c < 3; ++c) sum += a.at(x, y)[c];
    return sum / (3.0 * a.width * a.height);
}

}  // namespace

TEST_CASE("reference over triangles: a closed glTF box of albedo ρ emitting Lₑ has radiance Lₑ/(1−ρ)",
          "[gi][reference][gltf]") {
    // Twelve triangles, double-sided, albedo 0.5, emission 1: every ray sees 2. As the
    // analytic furnace: 24² pixels × 64 paths, the mean's standard deviation ≈ 0.3 %, so
    // within 1 %; every pixel within 25 %. A ray that slipped between two triangles of an
    // edge would leave the box and see black: the mean would fall.
    Rig rig(sceneWithModel("mesh_furnace", quadsGltf({cubeFaces(1.0f, 0)}, nlohmann::json::array({diffuse(glm::vec3(0.5f), glm::vec3(1.0f))})),
                           {{"walls", false}}),
            24);
    rig.app.camera().lookFrom({0.2f, 0.1f, 0.6f}, glm::normalize(glm::vec3(-0.3f, -0.2f, -1.0f)), 1.2f);
    const FloatImage img = renderReference(rig, 64, 8, 1);
    double worst = 0.0;
    for (int y = 0; y < img.height; ++y)
        for (int x = 0; x < img.width; ++x)
            for (int c = 0; c < 3; ++c) worst = std::max(worst, std::abs(img.at(x, y)[c] - 2.0));
    const double m = mean(img);
    INFO("mean " << m << ", worst pixel off by " << worst);
    CHECK(std::abs(m - 2.0) < 0.02);
    CHECK(worst < 0.5);
}

TEST_CASE("reference: the box's walls as glTF triangles equal the same walls as exact planes, within the noise",
          "[gi][reference][gltf]") {
    // The same room twice, lit by the box's lamp: once the box's own walls (planes), once
    // five glTF quads of the same colours with the walls off and the lamp kept. The floor's
    // rings are given one colour, which glTF can say. Unbiased both, so the walls-as-
    // triangles image differs from a plane image of another seed by noise alone: as much
    // as two plane images of two seeds differ (the noise floor), within 20 %. Measured
    // by the median difference (medianDifference says why): over five images of each
    // kind, pairs of planes read 0.050–0.053, of triangles 0.053, mixed 0.050–0.056. A
    // wall's colour 5 % off would add about 0.05 to most pixels' difference.
    const glm::vec3 floor(0.7f), left(0.95f, 0.45f, 0.1f), right(0.35f, 0.65f, 0.95f), other(0.85f, 0.82f, 0.78f);
    auto vec = [](glm::vec3 v) { return nlohmann::json{v.x, v.y, v.z}; };
    const nlohmann::json planesBox = {{"left", vec(left)},
                                      {"right", vec(right)},
                                      {"other", vec(other)},
                                      {"floor_wood", {{"light", vec(floor)}, {"dark", vec(floor)}}}};
    const std::string planes = writeScene("walls_as_planes.json", nlohmann::json({{"box", planesBox},
                                                                                   {"tumblers", nlohmann::json::array()},
                                                                                   {"marbles", nlohmann::json::array()},
                                                                                   {"fireballs", nlohmann::json::array()}})
                                                                      .dump());
    const std::vector<Quad> walls = {
        {{glm::vec3(-1, -1, -1), glm::vec3(1, -1, -1), glm::vec3(1, -1, 1), glm::vec3(-1, -1, 1)}, 0},  // floor
        {{glm::vec3(-1, 1, -1), glm::vec3(-1, 1, 1), glm::vec3(1, 1, 1), glm::vec3(1, 1, -1)}, 3},      // ceiling
        {{glm::vec3(-1, -1, -1), glm::vec3(-1, -1, 1), glm::vec3(-1, 1, 1), glm::vec3(-1, 1, -1)}, 1},  // left
        {{glm::vec3(1, -1, -1), glm::vec3(1, 1, -1), glm::vec3(1, 1, 1), glm::vec3(1, -1, 1)}, 2},      // right
        {{glm::vec3(-1, -1, -1), glm::vec3(-1, 1, -1), glm::vec3(1, 1, -1), glm::vec3(1, -1, -1)}, 3},  // back
    };
    const std::string triangles = sceneWithModel(
        "walls_as_triangles", quadsGltf({walls}, nlohmann::json::array({diffuse(floor), diffuse(left), diffuse(right), diffuse(other)})),
        {{"walls", false}, {"lamp", true}});

    constexpr int kSide = 24, kPaths = 128;
    auto render = [&](const std::string& scene, int seed) {
        Rig rig(scene, kSide);
        rig.app.camera() = app::Camera{};  // the box's camera, whatever the scene would frame
        return renderReference(rig, kPaths, 8, seed);
    };
    const FloatImage a = render(planes, 1), b = render(planes, 2), c = render(triangles, 3);
    const double floorNoise = medianDifference(a, b), difference = medianDifference(a, c);
    INFO("planes vs planes " << floorNoise << ", planes vs triangles " << difference << "; means " << mean(a) << ", "
                             << mean(b) << ", " << mean(c));
    CHECK(mean(a) > 0.05);  // the lamp lights the room
    CHECK(difference < 1.2 * floorNoise);
    CHECK(std::abs(mean(c) - mean(a)) < 0.02 * mean(a));
}

TEST_CASE("reference: a directional light on a glTF plate gives E·ρ/π, its shadow through the BVH is black, its rays counted",
          "[gi][reference][gltf]") {
    // A 4 m plate (albedo 0.5) at y = 0 under a sun of 3 lux shining straight down, and a
    // black 0.5 m square 0.5 m above it at x = 0.5. One light, picked every time, and no
    // light returning (the square is black, the plate flat): a lit pixel is exactly
    // 0.5/π × 3 (float rounding only), a shadowed one exactly 0.
    std::vector<Quad> quads = {
        {{glm::vec3(-2, 0, -2), glm::vec3(-2, 0, 2), glm::vec3(2, 0, 2), glm::vec3(2, 0, -2)}, 0},
        {{glm::vec3(0.25f, 0.5f, -0.25f), glm::vec3(0.25f, 0.5f, 0.25f), glm::vec3(0.75f, 0.5f, 0.25f),
          glm::vec3(0.75f, 0.5f, -0.25f)},
         1},
    };
    nlohmann::json gltf = quadsGltf({quads}, nlohmann::json::array({diffuse(glm::vec3(0.5f), glm::vec3(0.0f), false), diffuse(glm::vec3(0.0f))}));
    gltf["extensionsUsed"] = {"KHR_lights_punctual"};
    gltf["extensions"] = {{"KHR_lights_punctual", {{"lights", {{{"type", "directional"}, {"intensity", 3.0}}}}}}};
    // −Z turned to −y: −90° about x.
    gltf["nodes"].push_back({{"rotation", {-std::sqrt(0.5), 0.0, 0.0, std::sqrt(0.5)}},
                             {"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}});
    gltf["scenes"][0]["nodes"].push_back(1);
    constexpr int kSide = 32;
    Rig rig(sceneWithModel("sun_on_plate", gltf, {{"walls", false}}), kSide);
    rig.app.camera().lookFrom({0.0f, 2.0f, 2.0f}, glm::normalize(glm::vec3(0.0f, -2.0f, -2.0f)), 1.0f);
    const FloatImage radiance = renderReference(rig, 8, 2, 1);
    const FloatImage direct = rig.image("reference", "direct");
    const glm::mat4 vp = rig.app.camera().projection(1.0f) * rig.app.camera().view();
    auto pixel = [&](glm::vec3 world) {
        const glm::vec4 c = vp * glm::vec4(world, 1.0f);
        const glm::ivec2 p((glm::vec2(c) / c.w * 0.5f + 0.5f) * float(kSide));
        REQUIRE(p.x >= 0);
        REQUIRE(p.y >= 0);
        REQUIRE(p.x < kSide);
        REQUIRE(p.y < kSide);
        return p;
    };
    const float expected = 0.5f / kPi * 3.0f;
    for (glm::vec3 lit : {glm::vec3(-0.6f, 0, 0), glm::vec3(0.5f, 0, 0.8f), glm::vec3(-1.0f, 0, -1.0f)}) {
        const glm::ivec2 p = pixel(lit);
        INFO("lit at " << lit.x << ", " << lit.z << ": " << radiance.at(p.x, p.y)[0]);
        for (int c = 0; c < 3; ++c) {
            CHECK(radiance.at(p.x, p.y)[c] == Approx(expected).epsilon(1e-4));
            CHECK(direct.at(p.x, p.y)[c] == Approx(expected).epsilon(1e-4));
        }
    }
    const glm::ivec2 shadow = pixel({0.5f, 0.0f, 0.0f});
    INFO("in the shadow: " << radiance.at(shadow.x, shadow.y)[0]);
    CHECK(radiance.at(shadow.x, shadow.y)[0] == 0.0f);

    // The rays output counts what each pixel cost: where the camera sees past the plate,
    // one ray a path; on the lit plate far from the square, the camera's ray, the shadow
    // ray to the sun and the bounce that escapes (roulette starts at bounce 3) — three,
    // and a few more for the rare bounce that meets the square.
    const FloatImage rays = rig.image("reference", "rays");
    INFO("rays at the top row " << rays.at(kSide / 2, kSide - 1)[0]);
    CHECK(rays.at(kSide / 2, kSide - 1)[0] == 8.0f);
    const glm::ivec2 far = pixel({-1.0f, 0, -1.0f});
    INFO("rays on the plate " << rays.at(far.x, far.y)[0]);
    CHECK(rays.at(far.x, far.y)[0] >= 3 * 8.0f);
    CHECK(rays.at(far.x, far.y)[0] <= 4 * 8.0f);
}

TEST_CASE("reference vs an independent renderer: Embree on the CPU agrees on a room nobody tuned, within the noise",
          "[gi][reference][gltf][embree]") {
    // A room of coloured walls with a hole in its ceiling, a turned block, an emissive
    // panel and a point light: triangles through the host's two-level BVH on the GPU,
    // against Embree's over the same file's triangles placed by the loader's transforms.
    // Both unbiased: an image of each differs from the other by noise alone, as much as
    // two seeds of each differ among themselves — for the median difference m of
    // independent estimates, m(G,C)² ≈ (m(G,G')² + m(C,C')²)/2 — within 20 %, and the
    // means within 2 %.
    const std::vector<Quad> room = {
        {{glm::vec3(-2, 0, -2), glm::vec3(-2, 0, 2), glm::vec3(2, 0, 2), glm::vec3(2, 0, -2)}, 0},          // floor
        {{glm::vec3(-2, 0, -2), glm::vec3(2, 0, -2), glm::vec3(2, 2.5f, -2), glm::vec3(-2, 2.5f, -2)}, 1},  // back
        {{glm::vec3(-2, 0, -2), glm::vec3(-2, 2.5f, -2), glm::vec3(-2, 2.5f, 2), glm::vec3(-2, 0, 2)}, 2},  // left
        {{glm::vec3(2, 0, -2), glm::vec3(2, 0, 2), glm::vec3(2, 2.5f, 2), glm::vec3(2, 2.5f, -2)}, 3},      // right
        {{glm::vec3(-2, 2.5f, -2), glm::vec3(-2, 2.5f, 2), glm::vec3(0.5f, 2.5f, 2), glm::vec3(0.5f, 2.5f, -2)}, 4},
        {{glm::vec3(1.2f, 2.5f, -2), glm::vec3(1.2f, 2.5f, 2), glm::vec3(2, 2.5f, 2), glm::vec3(2, 2.5f, -2)}, 4},
        {{glm::vec3(-1.2f, 2.45f, -1), glm::vec3(-1.2f, 2.45f, -0.2f), glm::vec3(-0.4f, 2.45f, -0.2f),
          glm::vec3(-0.4f, 2.45f, -1)},
         5},  // the panel
    };
    nlohmann::json gltf = quadsGltf({room, cubeFaces(0.4f, 6)},
                                    nlohmann::json::array({diffuse({0.6f, 0.55f, 0.5f}), diffuse({0.3f, 0.5f, 0.7f}), diffuse({0.7f, 0.3f, 0.3f}),
                                     diffuse(glm::vec3(0.5f)), diffuse(glm::vec3(0.8f)),
                                     diffuse(glm::vec3(0.0f), {1.0f, 0.85f, 0.7f}), diffuse({0.8f, 0.8f, 0.3f})}));
    gltf["materials"][5]["extensions"] = {{"KHR_materials_emissive_strength", {{"emissiveStrength", 6.0}}}};
    gltf["extensionsUsed"] = {"KHR_lights_punctual", "KHR_materials_emissive_strength"};
    gltf["nodes"][1]["translation"] = {0.3, 0.4, -0.6};
    gltf["nodes"][1]["rotation"] = {0.0, std::sin(0.3), 0.0, std::cos(0.3)};  // 34° about y
    gltf["extensions"] = {
        {"KHR_lights_punctual", {{"lights", {{{"type", "point"}, {"intensity", 3.0}, {"color", {1.0, 0.9, 0.8}}}}}}}};
    gltf["nodes"].push_back({{"translation", {1.0, 1.8, 0.5}}, {"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}});
    gltf["scenes"][0]["nodes"].push_back(2);
    const std::string scene = sceneWithModel("untuned_room", gltf, {{"walls", false}});

    constexpr int kSide = 24, kPaths = 128;
    model::Model m;
    std::string error;
    REQUIRE(model::loadGltf(TEST_OUTPUT_DIR "/untuned_room.gltf", m, error));
    Rig rig(scene, kSide);
    rig.app.camera().lookFrom({0.0f, 1.3f, 4.5f}, glm::normalize(glm::vec3(0.0f, -0.3f, -5.5f)), 0.9f);
    const FloatImage g1 = renderReference(rig, kPaths, 8, 1), g2 = renderReference(rig, kPaths, 8, 2);
    CpuTraceSettings settings;
    settings.width = settings.height = kSide;
    settings.invViewProj = glm::inverse(rig.app.camera().projection(1.0f) * rig.app.camera().view());
    settings.samples = kPaths;
    FloatImage c1, c2;
    settings.seed = 1;
    REQUIRE(traceWithEmbree(m, settings, c1, error));
    settings.seed = 2;
    REQUIRE(traceWithEmbree(m, settings, c2, error));
    const double gpuNoise = medianDifference(g1, g2), cpuNoise = medianDifference(c1, c2),
                 between = medianDifference(g1, c1);
    const double expected = std::sqrt((gpuNoise * gpuNoise + cpuNoise * cpuNoise) / 2.0);
    WARN("median difference GPU/GPU " << gpuNoise << ", CPU/CPU " << cpuNoise << ", GPU/CPU " << between << " (noise alone: " << expected << "); means " << mean(g1) << ", " << mean(g2) << ", " << mean(c1) << ", " << mean(c2));
    CHECK(mean(g1) > 0.05);
    CHECK(between < 1.2 * expected);
    CHECK(std::abs(mean(g1) + mean(g2) - mean(c1) - mean(c2)) < 0.02 * (mean(c1) + mean(c2)));
}

TEST_CASE("reference: an emitting glTF square lights a plate as Lambert's polygon formula says (next-event estimation)",
          "[gi][reference][gltf]") {
    // A 0.4 m square 0.5 m above a plate (albedo 0.5) emits L = 5 downward (one-sided, so
    // the camera above sees through its back); nothing else. The plate's radiance is
    // ρ/π·E with E = L/2 · Σ Θᵢ n·(vᵢ × vᵢ₊₁)/|vᵢ × vᵢ₊₁| over the square's edges seen from
    // the point (the irradiance of a uniform polygon); light returning is nil (the square
    // is black, the plate flat). Sampled by power and a uniform point, weighted against the
    // cosine paths by MIS, 256 paths a pixel: each pixel within 5 % of the peak radiance
    // (measured: the worst of 528 pixels 3.3 %, and 6.0 % at 64 paths — noise, falling
    // as 1/√n), the mean over the plate within 1 % (measured 0.04 %).
    constexpr float kHalf = 0.2f, kHeight = 0.5f, kRadiance = 5.0f;
    std::vector<Quad> quads = {
        {{glm::vec3(-2, 0, -2), glm::vec3(-2, 0, 2), glm::vec3(2, 0, 2), glm::vec3(2, 0, -2)}, 0},
        {{glm::vec3(-kHalf, kHeight, -kHalf), glm::vec3(kHalf, kHeight, -kHalf), glm::vec3(kHalf, kHeight, kHalf),
          glm::vec3(-kHalf, kHeight, kHalf)},
         1},
    };
    nlohmann::json gltf = quadsGltf({quads}, nlohmann::json::array({diffuse(glm::vec3(0.5f), glm::vec3(0.0f), false),
                                                                    diffuse(glm::vec3(0.0f), glm::vec3(1.0f), false)}));
    gltf["materials"][1]["extensions"] = {{"KHR_materials_emissive_strength", {{"emissiveStrength", kRadiance}}}};
    gltf["extensionsUsed"] = {"KHR_materials_emissive_strength"};
    constexpr int kSide = 24;
    Rig rig(sceneWithModel("emitting_square", gltf, {{"walls", false}}), kSide);
    rig.app.camera().lookFrom({0.0f, 1.6f, 1.2f}, glm::normalize(glm::vec3(0.0f, -1.6f, -1.2f)), 1.0f);
    const FloatImage img = renderReference(rig, 256, 4, 1);
    const glm::mat4 inv = glm::inverse(rig.app.camera().projection(1.0f) * rig.app.camera().view());
    const std::array<glm::vec3, 4> square = {glm::vec3(-kHalf, kHeight, -kHalf), glm::vec3(kHalf, kHeight, -kHalf),
                                            glm::vec3(kHalf, kHeight, kHalf), glm::vec3(-kHalf, kHeight, kHalf)};
    auto irradiance = [&](glm::vec3 p) {
        double sum = 0.0;
        for (size_t i = 0; i < 4; ++i) {
            const glm::dvec3 a = glm::normalize(glm::dvec3(square[i] - p)), b = glm::normalize(glm::dvec3(square[(i + 1) % 4] - p));
            const glm::dvec3 c = glm::cross(a, b);
            sum += std::acos(std::clamp(glm::dot(a, b), -1.0, 1.0)) * c.y / glm::length(c);
        }
        return kRadiance / 2.0 * std::abs(sum);
    };
    double sumRef = 0.0, sumExpected = 0.0, worst = 0.0, peak = 0.0;
    int pixels = 0;
    for (int y = 0; y < kSide; ++y)
        for (int x = 0; x < kSide; ++x) {
            const glm::vec2 ndc = (glm::vec2(x, y) + 0.5f) / float(kSide) * 2.0f - 1.0f;
            const glm::vec4 n = inv * glm::vec4(ndc, -1, 1), f = inv * glm::vec4(ndc, 1, 1);
            const glm::vec3 o = glm::vec3(n) / n.w, d = glm::vec3(f) / f.w - o;
            if (d.y >= 0.0f) continue;
            const glm::vec3 p = o + d * (-o.y / d.y);
            if (std::abs(p.x) > 1.8f || std::abs(p.z) > 1.8f) continue;
            const double expected = 0.5 / kPi * irradiance(p), got = img.at(x, y)[1];
            sumRef += got, sumExpected += expected, ++pixels;
            worst = std::max(worst, std::abs(got - expected));
            peak = std::max(peak, expected);
        }
    INFO(pixels << " pixels on the plate: mean " << sumRef / pixels << " against " << sumExpected / pixels
                << ", worst pixel off by " << worst / peak * 100 << " % of the peak " << peak);
    REQUIRE(pixels > 300);
    CHECK(std::abs(sumRef - sumExpected) < 0.01 * sumExpected);
    CHECK(worst < 0.05 * peak);
    WARN("mean " << sumRef / pixels << " against " << sumExpected / pixels << "; worst pixel " << worst / peak * 100 << " % of the peak");
}
