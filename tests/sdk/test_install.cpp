// Kiln as an SDK, the way a user meets it: `cmake --install` to a prefix of its own, the
// example pass of examples/external_pass/ configured and built against that prefix in a
// separate tree (find_package(Kiln), kiln_add_pass), the installed kiln rendering with it
// headless, then the example rebuilt with a changed constant while that kiln runs, and
// the change seen in its output.
#include <catch2/catch.hpp>

#include <unistd.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <regex>
#include <string>
#include <thread>

#include "kiln/image_io.hpp"
#include "support/run_kiln.hpp"

namespace fs = std::filesystem;
using kiln::test::Background;
using kiln::test::runProgram;
using kiln::test::slurp;

namespace {

constexpr int kSize = 64;

std::string quoted(const fs::path& p) { return "'" + p.string() + "'"; }

// The worst difference, in 8-bit steps, between `image` and `original` × the example's
// vignette factor 1 − strength · 2r² (r from the centre, in texture coordinates).
double worstVignetteError(const kiln::FloatImage& original, const kiln::FloatImage& image, double strength) {
    double worst = 0;
    for (int y = 0; y < image.height; ++y)
        for (int x = 0; x < image.width; ++x) {
            const double u = (x + 0.5) / image.width - 0.5, v = (y + 0.5) / image.height - 0.5;
            const double factor = 1.0 - strength * 2.0 * (u * u + v * v);
            for (int c = 0; c < 3; ++c)
                worst = std::max(worst, std::abs(image.at(x, y)[c] - original.at(x, y)[c] * factor) * 255.0);
        }
    return worst;
}

// Reads the PNG once it is complete (kiln may be writing it): false until the deadline.
bool readWhenWritten(const fs::path& png, kiln::FloatImage& out) {
    std::string error;
    return fs::exists(png) && kiln::readPng(png.string(), out, error) && out.width == kSize && out.height == kSize;
}

}  // namespace

TEST_CASE("installed to a prefix, an out-of-tree pass builds against it and reloads live", "[sdk]") {
    const fs::path base = fs::path(TEST_OUTPUT_DIR) / ("install-" + std::to_string(getpid()));
    kiln::test::removeEarlierRuns(base);
    fs::create_directories(base / "work");
    const fs::path prefix = base / "prefix", example = base / "external_pass", exampleBuild = base / "external_pass-build";

    // 1. The layout.
    auto install = runProgram(CMAKE_COMMAND, "--install " + quoted(KILN_BUILD_DIR) + " --prefix " + quoted(prefix), 600);
    INFO(install.out << install.err);
    REQUIRE(install.exitCode == 0);
    for (const char* file : {"bin/kiln", "bin/kiln-sim", "lib/libkiln_core.so", "lib/libkiln_sim.so",
                             "lib/kiln/modules/libpass_gbuffer.so", "lib/kiln/modules/libpass_composite.so",
                             "include/kiln/pass.hpp", "include/kiln/scene_view.hpp", "include/kiln/loader/glad/gl.h",
                             "include/kiln/loader/KHR/khrplatform.h", "share/kiln/pipelines/default.json",
                             "share/kiln/shaders/common/fullscreen.vert", "share/kiln/scenes/cornell.json",
                             "share/kiln/scripts/plot.py", "lib/cmake/Kiln/KilnConfig.cmake",
                             "lib/cmake/Kiln/KilnConfigVersion.cmake", "lib/cmake/Kiln/KilnModule.cmake",
                             "lib/cmake/Kiln/KilnTargets.cmake"})
        CHECK(fs::exists(prefix / file));
    CHECK_FALSE(fs::exists(prefix / "include/kiln/module_loader.hpp"));  // the host's, not the SDK's
    const std::string kiln = (prefix / "bin/kiln").string();

    // 2. The installed kiln takes its files from the prefix, wherever it is run.
    auto help = runProgram(kiln, "--help", 60, (base / "work").string());
    CHECK(help.exitCode == 0);
    CHECK(help.out.find("the installation, " + (prefix / "share/kiln").string()) != std::string::npos);

    // 3. The example, copied so the test can edit it, built in a tree of its own.
    fs::copy(EXAMPLE_DIR, example, fs::copy_options::recursive);
    auto configure = runProgram(CMAKE_COMMAND, "-S " + quoted(example) + " -B " + quoted(exampleBuild) +
                                                   " -DCMAKE_BUILD_TYPE=Release -DCMAKE_PREFIX_PATH=" + quoted(prefix), 600);
    INFO(configure.out << configure.err);
    REQUIRE(configure.exitCode == 0);
    auto build = runProgram(CMAKE_COMMAND, "--build " + quoted(exampleBuild), 600);
    INFO(build.out << build.err);
    REQUIRE(build.exitCode == 0);
    REQUIRE(fs::exists(exampleBuild / "modules/libpass_vignette.so"));

    // 4. The example pipeline's image before the vignette (--view composite.color), then
    // its output, by a kiln that keeps running (--watch) with the example's shaders and
    // modules searched first.
    const std::string common = " --headless --size " + std::to_string(kSize) + "x" + std::to_string(kSize) + " --paused";
    const std::string exampleFiles = " --pipeline " + quoted(example / "pipelines/vignette.json") + " --shaders " +
                                      quoted(fs::path((example / "shaders").string() + ":")) + " --modules " +
                                      quoted(fs::path((exampleBuild / "modules").string() + ":"));
    auto plain = runProgram(kiln, common + exampleFiles + " --view composite.color --out " + quoted(base / "default.png"),
                            300, (base / "work").string());
    INFO(plain.err);
    REQUIRE(plain.exitCode == 0);
    kiln::FloatImage original, image;
    std::string error;
    REQUIRE(kiln::readPng((base / "default.png").string(), original, error));

    const fs::path out = base / "vignette.png", log = base / "watch.log";
    Background watching({kiln, "--headless", "--size", std::to_string(kSize) + "x" + std::to_string(kSize), "--paused",
                         "--watch", "--pipeline", (example / "pipelines/vignette.json").string(), "--shaders",
                         (example / "shaders").string() + ":", "--modules", (exampleBuild / "modules").string() + ":",
                         "--out", out.string()},
                        log.string(), (base / "work").string());
    REQUIRE(watching.started());
    auto waitFor = [&](auto&& done, std::chrono::seconds limit) {
        const auto deadline = std::chrono::steady_clock::now() + limit;
        while (!done() && watching.running() && std::chrono::steady_clock::now() < deadline)
            std::this_thread::sleep_for(std::chrono::milliseconds(100));
        return done();
    };
    const bool watchingStarted = waitFor([&] { return slurp(log).find("watching for edits") != std::string::npos; },
                                         std::chrono::seconds(300));
    INFO(slurp(log));
    REQUIRE(watchingStarted);
    REQUIRE(readWhenWritten(out, image));
    // Tolerance: one 8-bit step for the vignette's rounding to RGBA8, plus float slack.
    CHECK(worstVignetteError(original, image, 0.5) <= 1.01);
    CHECK(worstVignetteError(original, image, 0.8) > 10);  // the check can tell the two apart

    // 5. A changed constant, rebuilt while kiln runs: the next image has it.
    std::string source = slurp(example / "vignette.cpp");
    const std::regex constant("kStrength = 0\\.5f");
    REQUIRE(std::regex_search(source, constant));
    std::ofstream(example / "vignette.cpp", std::ios::trunc) << std::regex_replace(source, constant, "kStrength = 0.8f");
    auto rebuild = runProgram(CMAKE_COMMAND, "--build " + quoted(exampleBuild), 600);
    INFO(rebuild.out << rebuild.err);
    REQUIRE(rebuild.exitCode == 0);
    const bool changed = waitFor(
        [&] { return readWhenWritten(out, image) && worstVignetteError(original, image, 0.8) <= 1.01; },
        std::chrono::seconds(300));
    INFO(slurp(log));
    CHECK(changed);
    CHECK(slurp(log).find("reloaded module vignette") != std::string::npos);
    CHECK(watching.stop(std::chrono::seconds(60)) == 128 + SIGTERM);  // stopped as asked, as a shell reports it
    CHECK(slurp(log).find("stopped watching") != std::string::npos);
    CHECK(slurp(log).find("error") == std::string::npos);
}
