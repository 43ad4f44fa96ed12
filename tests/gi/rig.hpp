// The GI tests' rig: one App, headless and paused, with the GI test modules on the
// module path; scenes written to the test's output directory; pipelines from text.
#pragma once

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <catch2/catch.hpp>
#include <glm/glm.hpp>
#include <nlohmann/json.hpp>

#include "app/app.hpp"
#include "kiln/image_io.hpp"
#include "support/headless.hpp"

namespace kiln::test {

inline std::string writeScene(const std::string& name, const std::string& json) {
    std::filesystem::create_directories(TEST_OUTPUT_DIR);
    const std::filesystem::path file = std::filesystem::path(TEST_OUTPUT_DIR) / name;
    std::ofstream(file) << json;
    return file.string();
}
inline const char* kEmptyBox = R"({"tumblers": [], "marbles": [], "fireballs": []})";
// The white furnace: a closed box whose every surface (the floor's both wood colours and
// the lamp dome too: colour 0.5 × intensity 2) has albedo 0.5 and emits 1, so the
// radiance everywhere is 1/(1 − 0.5) = 2. Put the camera inside (distance 0.5).
inline const char* kFurnaceBox = R"({
    "box": {"left": [0.5, 0.5, 0.5], "right": [0.5, 0.5, 0.5], "other": [0.5, 0.5, 0.5],
            "floor_wood": {"light": [0.5, 0.5, 0.5], "dark": [0.5, 0.5, 0.5]},
            "emission": [1, 1, 1], "closed": true},
    "lamp": {"color": [0.5, 0.5, 0.5], "intensity": 2.0},
    "tumblers": [], "marbles": [], "fireballs": []})";

// One App, paused (time frozen), with the GI test module directory on the path.
struct Rig {
    app::App app;
    int size;
    Rig(const std::string& scene, int size_) : size(size_) {
        REQUIRE(test::ensureHeadlessContext());
        app::Options o;
        app::applyDefaults(o);
        if (!scene.empty()) o.scene = scene;
        o.moduleDir += std::string(":") + GI_TEST_MODULES;
        o.headless = true;
        o.live = false;
        o.width = o.height = size;
        o.paused = true;
        o.seed = 1;
        std::string error;
        INFO(error);
        REQUIRE(app.init(o, error));
    }
    // Loads a pipeline; `keep` are "pass.output" textures read back (un-culled).
    void load(const std::string& text, std::vector<std::string> keep = {}) {
        app.runtime().setRequested(std::move(keep));
        std::string errors;
        const bool ok = app.runtime().loadPipelineText(text, "test.json", errors);
        INFO(errors);
        REQUIRE(ok);
    }
    const TextureRef& tex(const std::string& pass, const std::string& name) {
        const TextureRef* t = app.runtime().findTexture(pass, name);
        REQUIRE(t);
        return *t;
    }
    FloatImage image(const std::string& pass, const std::string& name) {
        const TextureRef& t = tex(pass, name);
        return readTexture(t.id, t.target, t.format, t.width, t.height);
    }
    void checkNoErrors() {
        for (auto& e : app.runtime().activeErrors()) FAIL(e);
    }
};

// World position of pixel (x, y) from a G-buffer depth image and the rig's camera.
inline glm::vec3 worldOf(Rig& rig, const FloatImage& depth, int x, int y) {
    const glm::mat4 inv = glm::inverse(rig.app.camera().projection(1.0f) * rig.app.camera().view());
    glm::vec4 ndc((x + 0.5f) / rig.size * 2 - 1, (y + 0.5f) / rig.size * 2 - 1, depth.at(x, y)[0] * 2 - 1, 1);
    glm::vec4 w = inv * ndc;
    return glm::vec3(w) / w.w;
}

inline std::string pipeline(const std::string& output, const std::string& passes) {
    return R"({"output": ")" + output + R"(", "passes": [)" + passes + "]}";
}

// pipelines/default.json with `params` set on its pass `id`.
inline nlohmann::json defaultPipelineWith(const std::string& id, const nlohmann::json& params) {
    nlohmann::json p = nlohmann::json::parse(std::ifstream(KILN_SOURCE_DIR "/pipelines/default.json"));
    for (auto& pass : p["passes"])
        if (pass["id"] == id) pass["params"].update(params);
    return p;
}

}  // namespace kiln::test
