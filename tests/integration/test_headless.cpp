// Headless integration: the real host, the real modules and shaders, read back.
#include <catch2/catch.hpp>

#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include "app/app.hpp"
#include "kiln/image_io.hpp"
#include "support/headless.hpp"
#include "support/run_kiln.hpp"

namespace fs = std::filesystem;
using namespace kiln;
using kiln::test::Run;
using kiln::test::runKiln;

TEST_CASE("default pipeline: left wall reads orange, right wall sky blue", "[integration][gl]") {
    REQUIRE(test::ensureHeadlessContext());
    app::App app;
    std::string error;
    REQUIRE(app.init(test::pausedHeadlessOptions(128), error));
    app.runtime().setRequested({"composite.hdr"});  // written only when something reads it
    app.frame();
    // The hue is judged on linear radiance (composite.hdr): bounce light and the
    // tonemap's shoulder desaturate the final image, not the order of the channels.
    const TextureRef* hdr = app.runtime().findTexture("composite", "hdr");
    REQUIRE(hdr);
    FloatImage img = readTexture(hdr->id, hdr->target, hdr->format, hdr->width, hdr->height);
    REQUIRE(img.width == 128);
    // Mid-height, near the image edges: only the side walls are there (the box
    // opening fills the view). Row 0 is the bottom.
    const float* left = img.at(8, 64);
    const float* right = img.at(119, 64);
    INFO("left " << left[0] << " " << left[1] << " " << left[2] << "; right " << right[0] << " " << right[1] << " " << right[2]);
    // Orange (albedo 0.95, 0.45, 0.1): red > green > blue, red at least twice blue.
    CHECK(left[0] > left[1]);
    CHECK(left[1] > left[2]);
    CHECK(left[0] > 2.0f * left[2]);
    // Sky blue (albedo 0.35, 0.65, 0.95): blue > green > red, blue 1.5× red.
    CHECK(right[2] > right[1]);
    CHECK(right[1] > right[0]);
    CHECK(right[2] > 1.5f * right[0]);
    // Both clearly lit.
    CHECK(left[0] + left[1] + left[2] > 0.3f);
    CHECK(right[0] + right[1] + right[2] > 0.3f);
}

TEST_CASE("kiln --headless --out writes the final image", "[integration][cli]") {
    const std::string png = std::string(TEST_OUTPUT_DIR) + "/final.png";
    fs::remove(png);
    const fs::path dump = fs::path(TEST_OUTPUT_DIR) / "final-dump";
    fs::remove_all(dump);
    Run r = runKiln("--headless --size 64x48 --paused --out " + png + " --dump " + dump.string());
    INFO(r.err);
    REQUIRE(r.exitCode == 0);
    FloatImage out, graphOutput;
    std::string error;
    REQUIRE(readPng(png, out, error));
    REQUIRE(readPng((dump / "composite.color.png").string(), graphOutput, error));
    // The file is the graph output of the last frame, at the size asked for...
    CHECK(out.width == 64);
    CHECK(out.height == 48);
    REQUIRE(out.pixels.size() == graphOutput.pixels.size());
    CHECK(out.pixels == graphOutput.pixels);
    // ...and shows the box: the orange left wall and the sky-blue right wall at
    // mid-height (the 4:3 frame shows black beyond the box at its sides), in the linear
    // radiance the dump holds (tonemapping compresses the bright blue wall towards white:
    // in the PNG its b − r is 0.06). Both far from grey: albedo b/r 2.7 on the right, less
    // what the other walls bleed onto them (measured: left r/b ≈ 19, right b/r ≈ 1.56).
    FloatImage hdr;
    REQUIRE(readExr((dump / "composite.hdr.exr").string(), hdr, error));
    const float* left = hdr.at(14, 24);
    const float* right = hdr.at(49, 24);
    INFO("left " << left[0] << " " << left[2] << ", right " << right[0] << " " << right[2]);
    CHECK(left[0] > 2.0f * left[2]);
    CHECK(right[2] > 1.4f * right[0]);
}

TEST_CASE("kiln --dump writes one PNG per texture, OpenEXR for float and depth", "[integration][cli]") {
    const fs::path dir = fs::path(TEST_OUTPUT_DIR) / "dump";
    fs::remove_all(dir);
    Run r = runKiln("--headless --size 64x64 --paused --dump " + dir.string());
    INFO(r.err);
    REQUIRE(r.exitCode == 0);
    std::set<std::string> files;
    for (auto& e : fs::directory_iterator(dir)) files.insert(e.path().filename().string());
    const std::set<std::string> expected = {
        "gbuffer.albedo.png", "gbuffer.normal.png", "gbuffer.normal.exr", "gbuffer.emissive.png",
        "gbuffer.emissive.exr", "gbuffer.depth.png", "gbuffer.depth.exr", "composite.color.png",
        "composite.hdr.png", "composite.hdr.exr"};
    for (auto& f : expected) {
        INFO(f);
        CHECK(files.count(f) == 1);
    }
}

TEST_CASE("kiln --stats prints a row per pass with a GPU time", "[integration][cli]") {
    Run r = runKiln("--headless --size 64x64 --frames 4 --no-skip --stats");
    INFO(r.err);
    REQUIRE(r.exitCode == 0);
    std::istringstream lines(r.out);
    std::string line;
    int rows = 0;
    while (std::getline(lines, line)) {
        std::istringstream cols(line);
        std::string id, module, state, gpu;
        cols >> id >> module >> state >> gpu;
        if (id == "gbuffer" || id == "composite") {
            ++rows;
            CHECK(state == "ran");
            CHECK(std::stod(gpu) > 0.0);  // a real timer-query figure, not "-"
        }
    }
    CHECK(rows == 2);
}

TEST_CASE("a bad pipeline exits non-zero with the JSON path on stderr", "[integration][cli]") {
    fs::create_directories(TEST_OUTPUT_DIR);
    const fs::path file = fs::path(TEST_OUTPUT_DIR) / "bad.json";
    std::ofstream(file) << R"({"output": "composite.color", "passes": [ {"id": "gbuffer", "module": "gbufer"} ]})";
    Run r = runKiln("--headless --size 32x32 --stats --pipeline " + file.string());
    CHECK(r.exitCode != 0);
    CHECK_THAT(r.err, Catch::Contains("passes[0].module"));
    CHECK_THAT(r.err, Catch::Contains("gbuffer"));  // the suggestion
}

TEST_CASE("bad command lines exit 2 with one line on stderr", "[integration][cli]") {
    for (const char* args : {"--size 12", "--frames -3", "--bogus", "--pipeline"}) {
        INFO(args);
        Run r = runKiln(args);
        CHECK(r.exitCode == 2);
        CHECK(std::count(r.err.begin(), r.err.end(), '\n') == 1);
    }
}

TEST_CASE("default files come from a Kiln tree in the working directory, else the source tree, and an empty list entry is the shipped one", "[integration][cli]") {
    // A copied tree whose pipeline is broken: run from inside the copy, kiln must read
    // (and name) the copy's file, not the source tree's it was built from.
    const fs::path copy = fs::path(TEST_OUTPUT_DIR) / ("tree-copy-" + std::to_string(getpid()));
    fs::remove_all(copy);
    fs::create_directories(copy / "pipelines");
    fs::copy(fs::path(KILN_SOURCE_DIR) / "shaders", copy / "shaders", fs::copy_options::recursive);
    fs::copy(fs::path(KILN_SOURCE_DIR) / "scenes", copy / "scenes", fs::copy_options::recursive);
    std::ofstream(copy / "pipelines/default.json") << "{ broken";
    const Run inCopy = runKiln("--headless --size 16x16 --stats", 60, copy.string());
    INFO(inCopy.err);
    CHECK(inCopy.exitCode == 1);
    CHECK_THAT(inCopy.err, Catch::Contains((copy / "pipelines/default.json").string()));
    const Run help = runKiln("--help", 60, copy.string());
    CHECK_THAT(help.out, Catch::Contains("Default pipeline, scene and shaders come from " + copy.string()));

    // Outside any tree: the source tree's files, which render.
    const fs::path empty = fs::path(TEST_OUTPUT_DIR) / ("no-tree-" + std::to_string(getpid()));
    fs::create_directories(empty);
    const Run outside = runKiln("--headless --size 16x16 --out " + (empty / "o.png").string(), 120, empty.string());
    INFO(outside.err);
    CHECK(outside.exitCode == 0);
    CHECK(fs::file_size(empty / "o.png") > 0);
    CHECK_THAT(runKiln("--help", 60, empty.string()).out,
               Catch::Contains("the source tree Kiln was built from, " + std::string(KILN_SOURCE_DIR)));

    // An empty entry in --shaders/--modules stands for the shipped directory: a list of
    // an empty directory and it renders; the same list without it finds no pass.
    const std::string lists = " --stats --shaders " + empty.string() + ": --modules " + empty.string();
    const Run withShipped = runKiln("--headless --size 16x16" + lists + ":", 120, empty.string());
    INFO(withShipped.err);
    CHECK(withShipped.exitCode == 0);
    const Run without = runKiln("--headless --size 16x16" + lists, 120, empty.string());
    CHECK(without.exitCode == 1);
    CHECK_THAT(without.err, Catch::Contains("no module \"gbuffer\""));
    fs::remove_all(copy);
    fs::remove_all(empty);
}
