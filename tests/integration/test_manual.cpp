// The pass author's manual (the comment at the top of kiln/pass.hpp) is compiled: its
// example pass ships as passes/tint/ and shaders/tint/tint.frag, the text and the files
// are checked to be the same, and the built module is run and its pixels checked.
#include <catch2/catch.hpp>

#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "app/app.hpp"
#include "kiln/image_io.hpp"
#include "support/headless.hpp"

namespace fs = std::filesystem;
using namespace kiln;

namespace {

std::string readFile(const fs::path& p) {
    std::ifstream in(p);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
}

// The lines of `header` from the one starting with `first` to the one starting with
// `last` (both after the comment prefix "//     "), with that prefix removed.
std::string manualExample(const std::string& header, const std::string& first, const std::string& last) {
    const std::string prefix = "//     ";
    std::istringstream lines(header);
    std::string line, out;
    bool inside = false;
    while (std::getline(lines, line)) {
        const bool example = line.rfind(prefix, 0) == 0;
        const std::string text = example ? line.substr(prefix.size()) : "";
        if (!inside && example && text.rfind(first, 0) == 0) inside = true;
        if (!inside) continue;
        if (!example) FAIL("the manual's example is cut by the line \"" << line << "\"");
        out += text + "\n";
        if (text.rfind(last, 0) == 0) return out;
    }
    FAIL("pass.hpp has no example from \"" << first << "\" to \"" << last << "\"");
    return out;
}

}  // namespace

TEST_CASE("the pass manual's example is passes/tint/ and shaders/tint/tint.frag, word for word", "[integration][files]") {
    const fs::path root(KILN_SOURCE_DIR);
    const std::string header = readFile(root / "host/include/kiln/pass.hpp");
    CHECK(manualExample(header, "#include <kiln/pass.hpp>", "KILN_PASS_MODULE(tint, Tint)") ==
          readFile(root / "passes/tint/tint.cpp"));
    CHECK(manualExample(header, "#version 450 core", "void main()") == readFile(root / "shaders/tint/tint.frag"));
    // The manual's CMake line, with <name> as tint.
    CHECK(header.find("//   passes/<name>/CMakeLists.txt:   kiln_add_pass(<name> <name>.cpp)") != std::string::npos);
    CHECK(readFile(root / "passes/tint/CMakeLists.txt") == "kiln_add_pass(tint tint.cpp)\n");
}

TEST_CASE("the manual's tint pass multiplies what it reads by its tint, its parameter from the pipeline", "[integration][gl]") {
    REQUIRE(test::ensureHeadlessContext());
    app::App app;
    std::string error;
    REQUIRE(app.init(test::pausedHeadlessOptions(32), error));
    // composite.hdr (RGBA16F) in, so the ratio is exact up to half precision.
    const std::string pipeline = R"({"output": "tint.color", "passes": [
          {"id": "gbuffer", "module": "gbuffer"},
          {"id": "composite", "module": "composite",
           "inputs": {"albedo": "gbuffer.albedo", "normal": "gbuffer.normal", "depth": "gbuffer.depth"}},
          {"id": "tint", "module": "tint", "params": {"tint": [0.25, 1.0, 2.0]}, "inputs": {"color": "composite.hdr"}}]})";
    app.runtime().setRequested({"composite.hdr"});
    std::string errors;
    INFO(errors);
    REQUIRE(app.runtime().loadPipelineText(pipeline, "manual.json", errors));
    app.frame();
    for (auto& e : app.runtime().activeErrors()) FAIL(e);
    const FloatImage before = test::readOutput(app, "composite", "hdr");
    const FloatImage after = test::readOutput(app, "tint", "color");
    REQUIRE(after.width == before.width);
    const float tint[3] = {0.25f, 1.0f, 2.0f};
    int lit = 0;
    for (int y = 0; y < after.height; ++y)
        for (int x = 0; x < after.width; ++x)
            for (int c = 0; c < 3; ++c) {
                const float expected = before.at(x, y)[c] * tint[c];
                // Both are RGBA16F: 2^-10 relative per value, twice; same pixel centres.
                INFO("pixel " << x << "," << y << " channel " << c);
                REQUIRE(std::abs(after.at(x, y)[c] - expected) <= 2e-3f * std::abs(expected) + 1e-6f);
                lit += expected > 0.01f;
            }
    CHECK(lit > after.width * after.height);  // the box is lit: the check compared real values
}

TEST_CASE("several shader roots (--shaders A:B): the first that has a file wins, the others fill in", "[integration][gl]") {
    REQUIRE(test::ensureHeadlessContext());
    // A root of one's own with only tint/tint.frag (a constant green), ahead of Kiln's.
    const fs::path mine = fs::path(TEST_OUTPUT_DIR) / "shader-roots" / "mine";
    fs::remove_all(mine.parent_path());
    fs::create_directories(mine / "tint");
    std::ofstream(mine / "tint/tint.frag") << "#version 450 core\nlayout(location = 0) out vec4 o_color;\n"
                                              "void main() { o_color = vec4(0.0, 1.0, 0.0, 1.0); }\n";
    const std::string pipeline = R"({"output": "tint.color", "passes": [
          {"id": "gbuffer", "module": "gbuffer"},
          {"id": "composite", "module": "composite",
           "inputs": {"albedo": "gbuffer.albedo", "normal": "gbuffer.normal", "depth": "gbuffer.depth"}},
          {"id": "tint", "module": "tint", "inputs": {"color": "composite.hdr"}}]})";
    auto centre = [&](const std::string& roots) {
        app::Options o = test::pausedHeadlessOptions(16);
        o.shaderRoot = roots;
        app::App app;
        std::string error;
        INFO(error);
        REQUIRE(app.init(o, error));
        REQUIRE(app.runtime().loadPipelineText(pipeline, "roots.json", error));
        app.frame();
        for (auto& e : app.runtime().activeErrors()) FAIL(e);
        const TextureRef* t = app.runtime().findTexture("tint", "color");
        REQUIRE(t);
        const FloatImage img = readTexture(t->id, t->target, t->format, t->width, t->height);
        const float* p = img.at(8, 8);
        return std::array<float, 3>{p[0], p[1], p[2]};
    };
    const std::string kilns = std::string(KILN_SOURCE_DIR) + "/shaders";
    // Kiln's root alone: the manual's tint of the lit box (red kept, green and blue halved).
    const auto tinted = centre(kilns);
    CHECK_FALSE((tinted[0] == 0.0f && tinted[1] == 1.0f && tinted[2] == 0.0f));
    // Mine first: its tint.frag wins; gbuffer's and composite's shaders (and
    // common/fullscreen.vert, which mine lacks) come from Kiln's root.
    const auto green = centre(mine.string() + ":" + kilns);
    CHECK(green[0] == 0.0f);
    CHECK(green[1] == 1.0f);
    CHECK(green[2] == 0.0f);
}
