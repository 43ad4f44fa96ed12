// The live tests' sandbox: a temporary copy of the project's shaders, pipelines and
// scene with an App running headless on it, and the ways an editor or a build writes
// a file. Frames are waited on with a generous deadline, never a fixed time.
#pragma once

#include <catch2/catch.hpp>

#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>
#include <thread>

#include "app/app.hpp"
#include "app/editable_copy.hpp"
#include "kiln/image_io.hpp"
#include "support/headless.hpp"

namespace kiln::test {

namespace fs = std::filesystem;

inline std::string slurp(const fs::path& p) { return app::readWholeFile(p); }
inline void writeInPlace(const fs::path& p, const std::string& text) { std::ofstream(p, std::ios::trunc) << text; }
inline void writeByRename(const fs::path& p, const std::string& text) { app::saveByRename(p, text); }

struct Sandbox {
    app::EditableCopy copy;
    fs::path root;
    app::App app;

    // `prepare` runs on the copied tree before the app starts (e.g. installs a module).
    explicit Sandbox(const std::string& name, const std::string& pipeline = "default.json",
                     const std::string& pipelineText = {}, std::function<void(const fs::path&)> prepare = {})
        : copy(fs::path(TEST_OUTPUT_DIR) / (name + "-" + std::to_string(getpid())), KILN_SOURCE_DIR), root(copy.root()) {
        REQUIRE(test::ensureHeadlessContext());
        if (!pipelineText.empty()) writeInPlace(root / "pipelines" / pipeline, pipelineText);
        if (prepare) prepare(root);
        app::Options o;
        app::applyDefaults(o);
        o.headless = true;
        o.width = o.height = 32;
        o.paused = true;
        copy.pointAt(o, pipeline);
        std::string error;
        REQUIRE(app.init(o, error));
        app.frame();
        app.settle();  // a still frame to compare with (the default's voxel bounces converge over frames)
    }

    // Renders frames until `done` holds; false after 30 s (a generous bound: CI machines
    // get busy, and the sanitizer build is slow).
    template <class F>
    bool waitFor(F done) {
        const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(30);
        while (std::chrono::steady_clock::now() < until) {
            app.frame();
            if (done()) return true;
            std::this_thread::sleep_for(std::chrono::milliseconds(10));
        }
        return false;
    }
    glm::vec4 centre() { return centreOf(app.displayedTexture()); }
    // The centre texel of a pass's texture ("pass.output"); NaN when there is none.
    glm::vec4 centreOf(const std::string& qualified) {
        auto named = app.runtime().namedTexture(qualified);
        return named ? centreOf(&named->ref) : glm::vec4(NAN);
    }
    glm::vec4 centreOf(const TextureRef* t) {
        FloatImage img = readTexture(t->id, t->target, t->format, t->width, t->height);
        const float* p = img.at(img.width / 2, img.height / 2);
        return {p[0], p[1], p[2], p[3]};
    }
    bool errorMentions(const std::string& text) {
        for (auto& e : app.runtime().activeErrors())
            if (e.find(text) != std::string::npos) return true;
        return false;
    }
};

inline bool near(glm::vec4 a, glm::vec3 b) { return glm::length(glm::vec3(a) - b) < 0.02f; }

}  // namespace kiln::test
