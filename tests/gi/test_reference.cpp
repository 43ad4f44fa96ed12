// The path-traced reference (passes/reference) proven against what is known without
// it: the white furnace's closed form, determinism, and Monte Carlo convergence.
// Small images (≤ 32²) keep llvmpipe fast; tolerances say where they come from.
#include <catch2/catch.hpp>

#include <cmath>
#include <cstring>

#include <nlohmann/json.hpp>

#include "gi/rig.hpp"

using namespace kiln;
using namespace kiln::test;

namespace {

// Every requested path in its frame (no time budget), whatever the machine's speed.
std::string referencePipeline(int samplesPerFrame, int seed, int maxBounces = 16) {
    return pipeline("reference.radiance", R"({"id": "reference", "module": "reference", "params": {"samples_per_frame": )" +
                                              std::to_string(samplesPerFrame) + R"(, "seed": )" + std::to_string(seed) +
                                              R"(, "max_bounces": )" + std::to_string(maxBounces) + R"(, "budget_ms": 0}})");
}

// Renders `samples` paths per pixel in `frames` frames and reads the mean back.
FloatImage render(Rig& rig, int samples, int seed, int frames = 1, int maxBounces = 16) {
    rig.load(referencePipeline(samples / frames, seed, maxBounces));
    for (int f = 0; f < frames; ++f) rig.app.frame();
    rig.checkNoErrors();
    FloatImage img = rig.image("reference", "radiance");
    REQUIRE(img.at(0, 0)[3] == float(samples));  // alpha counts the paths
    return img;
}

double rmse(const FloatImage& a, const FloatImage& b) {
    double sum = 0.0;
    for (int y = 0; y < a.height; ++y)
        for (int x = 0; x < a.width; ++x)
            for (int c = 0; c < 3; ++c) sum += std::pow(double(a.at(x, y)[c]) - b.at(x, y)[c], 2);
    return std::sqrt(sum / (3.0 * a.width * a.height));
}

// The shipped scene without its fireballs.
std::string stillScene() {
    nlohmann::json scene = nlohmann::json::parse(std::ifstream(KILN_SOURCE_DIR "/scenes/cornell.json"));
    scene["fireballs"] = nlohmann::json::array();
    return writeScene("still.json", scene.dump());
}

}  // namespace

TEST_CASE("reference: white furnace — a closed box of albedo ρ emitting Lₑ everywhere has radiance Lₑ/(1−ρ)",
          "[gi][reference]") {
    // Every wall, the floor (both wood colours) and the lamp dome have albedo 0.5 and
    // emit 1 (the lamp: colour 0.5 × intensity 2), the front is closed and the camera
    // inside: every ray sees 1/(1 − 0.5) = 2. Russian roulette keeps the estimator
    // unbiased, so the mean over 32² pixels × 64 paths (65 536 paths; the per-path
    // standard deviation here is ≈ 1.4, so the mean's is ≈ 0.006 = 0.3 %) must be within
    // 1 % of 2, and every pixel within 25 % (64 paths each: ≈ 9 % standard deviation).
    Rig rig(writeScene("furnace.json", kFurnaceBox), 32);
    rig.app.camera().distance = 0.5f;  // inside the box, looking at the back wall
    FloatImage img = render(rig, 64, 1, 4, 256);
    double sum = 0.0, worst = 0.0;
    for (int y = 0; y < img.height; ++y)
        for (int x = 0; x < img.width; ++x)
            for (int c = 0; c < 3; ++c) {
                sum += img.at(x, y)[c];
                worst = std::max(worst, std::abs(img.at(x, y)[c] - 2.0));
            }
    const double mean = sum / (3.0 * img.width * img.height);
    INFO("mean " << mean << ", worst pixel off by " << worst);
    CHECK(std::abs(mean - 2.0) < 0.02);
    CHECK(worst < 0.5);
}

TEST_CASE("reference: 256 paths in one frame equal 256 paths over 32 frames (no path is lost)", "[gi][reference]") {
    // llvmpipe ends a shader loop after 65 535 iterations without a word; with 256 paths
    // in one invocation the last ~40 returned nothing and the image was 16 % dark. The
    // two means differ only by noise: same seed, same paths, another summation order
    // (float rounding, ≤ 1e-4 relative).
    Rig rig(stillScene(), 16);
    const FloatImage once = render(rig, 256, 3, 1);
    const FloatImage spread = render(rig, 256, 3, 32);
    double a = 0.0, b = 0.0;
    for (size_t i = 0; i < once.pixels.size(); i += 4) a += once.pixels[i + 1], b += spread.pixels[i + 1];
    INFO("mean green " << a / (once.pixels.size() / 4) << " vs " << b / (spread.pixels.size() / 4));
    CHECK(std::abs(a - b) <= 1e-4 * b);
}

TEST_CASE("reference: a frame stopped by its time budget goes on next frame, and the image is the same bit for bit",
          "[gi][reference]") {
    // 136 rows are three bands (64, 64, 8). With a budget of 1 ms a frame stops after the
    // first band whose dispatch outlasts it, wherever the machine's speed puts that; so
    // what is asserted holds at any speed: after every frame each band holds the paths of
    // the passes before it or one pass more, the later bands never ahead of the earlier,
    // and once converged the image equals one rendered without a budget, bit for bit.
    const std::string scene = stillScene();
    auto pipelineWith = [](int budgetMs) {
        return pipeline("reference.radiance",
                        R"({"id": "reference", "module": "reference", "params": {"samples_per_frame": 2, )"
                        R"("max_samples": 6, "budget_ms": )" + std::to_string(budgetMs) + "}}");
    };
    FloatImage whole, budgeted;
    {
        Rig rig(scene, 136);
        rig.load(pipelineWith(0));
        for (int f = 0; f < 3; ++f) rig.app.frame();
        whole = rig.image("reference", "radiance");
        REQUIRE(whole.at(0, 135)[3] == 6.0f);
    }
    Rig rig(scene, 136);
    rig.load(pipelineWith(1));
    int frames = 0;
    for (; frames < 200; ++frames) {
        rig.app.frame();
        rig.checkNoErrors();
        budgeted = rig.image("reference", "radiance");
        const float bands[3] = {budgeted.at(5, 0)[3], budgeted.at(5, 64)[3], budgeted.at(5, 128)[3]};
        INFO("frame " << frames << ": paths " << bands[0] << ", " << bands[1] << ", " << bands[2]);
        for (int b = 0; b < 3; ++b) {
            const int rows = b < 2 ? 64 : 8;
            for (int y = b * 64; y < b * 64 + rows; ++y) REQUIRE(budgeted.at(131, y)[3] == bands[b]);  // a band moves whole
        }
        CHECK(bands[0] >= bands[1]);
        CHECK(bands[1] >= bands[2]);
        CHECK(bands[0] - bands[2] <= 2.0f);
        if (bands[2] == 6.0f) break;
    }
    WARN("converged in " << frames + 1 << " frames of 1 ms budget (3 without)");
    REQUIRE(budgeted.pixels.size() == whole.pixels.size());
    CHECK(std::memcmp(budgeted.pixels.data(), whole.pixels.data(), whole.pixels.size() * sizeof(float)) == 0);
}

TEST_CASE("reference: the same seed gives the same image bit for bit, another seed another image",
          "[gi][reference]") {
    const std::string scene = stillScene();
    FloatImage a, b, c;
    {
        Rig rig(scene, 16);
        a = render(rig, 8, 7, 2);
    }
    {
        Rig rig(scene, 16);
        b = render(rig, 8, 7, 2);
        c = render(rig, 8, 8, 2);
    }
    REQUIRE(a.pixels.size() == b.pixels.size());
    CHECK(std::memcmp(a.pixels.data(), b.pixels.data(), a.pixels.size() * sizeof(float)) == 0);
    CHECK(rmse(a, c) > 0.0);
}

TEST_CASE("reference: error against an independent long run falls as 1/√spp", "[gi][reference]") {
    // Shipped scene without fireballs (their particles make rare, huge samples that
    // need far more paths for the RMSE itself to settle), time frozen, 24² pixels.
    // Against an independent 1024-path run (another seed) the expected RMSE is
    // σ·√(1/n + 1/1024): 16 → 256 paths should shrink it by √((1/16+1/1024)/(1/256+1/1024))
    // = 3.61. Over 576 pixels the ratio is itself an estimate; accept 2.7 … 4.6 (±25 %).
    const std::string scene = stillScene();
    Rig rig(scene, 24);
    const FloatImage truth = render(rig, 1024, 99, 4);
    const double e16 = rmse(render(rig, 16, 1), truth);
    const double e256 = rmse(render(rig, 256, 1, 2), truth);
    INFO("RMSE at 16 paths " << e16 << ", at 256 paths " << e256 << ", ratio " << e16 / e256);
    CHECK(e16 / e256 > 2.7);
    CHECK(e16 / e256 < 4.6);
}

TEST_CASE("reference vs rasterizer: the lamp's direct light on a floor agrees (one lamp, two models)",
          "[gi][reference]") {
    // Black walls, a uniform floor of albedo 0.8, nothing else: composite.hdr (lamp by
    // the 32-point cap quadrature, hard shadow test, no indirect, no ambient) against the
    // reference's direct output (the lamp sampled over its sphere, 256 paths). The floor
    // sees the whole cap, so only the quadrature (≲ 0.5 % here) and Monte Carlo noise
    // (≈ 0.3 % over the floor's mean) separate them: the means agree within 2 %, and the
    // RMSE over floor pixels stays under 5 % of the mean (jitter: edge pixels differ).
    // The lamp's own pixels carry the same emission in both.
    Rig rig(writeScene("direct_floor.json", R"({
        "box": {"left": [0, 0, 0], "right": [0, 0, 0], "other": [0, 0, 0],
                "floor_wood": {"light": [0.8, 0.8, 0.8], "dark": [0.8, 0.8, 0.8]}},
        "tumblers": [], "marbles": [], "fireballs": []})"),
            32);
    rig.load(pipeline("composite.hdr", R"(
        {"id": "gbuffer", "module": "gbuffer"},
        {"id": "shadow", "module": "shadow", "params": {"size": 512}},
        {"id": "composite", "module": "composite", "params": {"ambient": 0.0, "pcf": 1},
         "inputs": {"albedo": "gbuffer.albedo", "normal": "gbuffer.normal", "depth": "gbuffer.depth",
                    "emissive": "gbuffer.emissive", "shadow_map": "shadow.depth"}},
        {"id": "reference", "module": "reference", "params": {"samples_per_frame": 64, "jitter": false}})"),
             {"reference.direct", "gbuffer.normal"});
    for (int f = 0; f < 4; ++f) rig.app.frame();
    rig.checkNoErrors();
    const FloatImage raster = rig.image("composite", "hdr");
    const FloatImage ref = rig.image("reference", "direct");
    const FloatImage normal = rig.image("gbuffer", "normal");
    REQUIRE(ref.at(0, 0)[3] == 256.0f);
    double sumR = 0, sumT = 0, sq = 0;
    int n = 0;
    for (int y = 0; y < raster.height; ++y)
        for (int x = 0; x < raster.width; ++x) {
            if (normal.at(x, y)[1] < 0.9f || normal.at(x, y)[3] < 0.5f) continue;  // the floor faces +y
            sumR += raster.at(x, y)[1], sumT += ref.at(x, y)[1];
            sq += std::pow(double(raster.at(x, y)[1]) - ref.at(x, y)[1], 2);
            ++n;
        }
    REQUIRE(n > 100);
    const double meanR = sumR / n, meanT = sumT / n, rel = std::sqrt(sq / n) / meanT;
    INFO("floor: rasterizer " << meanR << ", reference " << meanT << " over " << n << " px; RMSE/mean " << rel);
    WARN("direct-light agreement on the floor: rasterizer " << meanR << ", reference " << meanT << ", RMSE/mean " << rel);
    CHECK(std::abs(meanR / meanT - 1.0) < 0.02);
    CHECK(rel < 0.05);
}

TEST_CASE("error pass: an image against itself is black, a darker one reads blue in signed mode",
          "[gi][reference]") {
    Rig rig(stillScene(), 16);
    auto run = [&](const std::string& image, const std::string& mode, bool legend = false) {
        rig.load(pipeline("error.color", R"({"id": "reference", "module": "reference", "params": {"samples_per_frame": 4}},
            {"id": "error", "module": "error", "inputs": {"image": ")" + image + R"(", "reference": "reference.radiance"},
             "params": {"mode": ")" + mode + R"(", "legend": )" + (legend ? "true" : "false") + "}}"));
        rig.app.frame();
        rig.checkNoErrors();
        return rig.image("error", "color");
    };
    const FloatImage same = run("reference.radiance", "relative");
    for (float v : same.pixels) CHECK((v == 0.0f || v == 1.0f));  // rgb black, alpha 1
    // direct ≤ total everywhere (the indirect part is ≥ 0): never red, and blue where
    // the indirect light is (most of the room).
    const FloatImage darker = run("reference.direct", "signed");
    int blue = 0;
    for (int y = 0; y < darker.height; ++y)
        for (int x = 0; x < darker.width; ++x) {
            const float* p = darker.at(x, y);
            CHECK(p[0] <= p[2] + 1e-6f);
            blue += p[2] > 0.99f && p[0] < 0.95f;
        }
    CHECK(blue > darker.width * darker.height / 4);
    // The legend (16 px: the whole of this image): the map left to right along the bottom
    // row, black to white (relative), blue to red (signed).
    const FloatImage relative = run("reference.radiance", "relative", true), signedMap = run("reference.direct", "signed", true);
    const float* left = relative.at(0, 0);
    const float* right = relative.at(relative.width - 1, 0);
    CHECK(left[0] + left[1] + left[2] < 0.1f);
    CHECK(right[0] + right[1] + right[2] > 2.7f);
    CHECK(signedMap.at(0, 0)[2] > 0.9f);
    CHECK(signedMap.at(0, 0)[0] < 0.2f);
    CHECK(signedMap.at(signedMap.width - 1, 0)[0] > 0.9f);
    CHECK(signedMap.at(signedMap.width - 1, 0)[2] < 0.2f);
}
