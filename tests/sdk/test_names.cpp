// The pass SDK describes a scene model, not one scene: no header a pass author gets from
// an installation names the demo's objects. The headers are the installed ones, so a
// header added to the SDK is checked without this test knowing of it.
#include <catch2/catch.hpp>

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <regex>
#include <string>

#include "support/run_kiln.hpp"

namespace fs = std::filesystem;

TEST_CASE("the installed SDK headers name no object of the demo scene", "[sdk]") {
    const fs::path prefix = fs::path(TEST_OUTPUT_DIR) / ("names-" + std::to_string(getpid()));
    kiln::test::removeEarlierRuns(prefix);
    auto install = kiln::test::runProgram(CMAKE_COMMAND, "--install '" + std::string(KILN_BUILD_DIR) + "' --prefix '" +
                                                             prefix.string() + "'", 600);
    INFO(install.out << install.err);
    REQUIRE(install.exitCode == 0);
    // The Cornell box's objects and their materials; "wall" and "sphere" are any scene's.
    const std::regex demo(R"(\b(cornell|tumblers?|roly-poly|marbles?|fireballs?|wood|lamps?|domes?|the box)\b)",
                          std::regex::icase);
    int headers = 0;
    std::string found;
    for (const fs::directory_entry& e : fs::recursive_directory_iterator(prefix / "include/kiln")) {
        if (!e.is_regular_file() || e.path().extension() != ".hpp") continue;  // the GL loader is glad's .h
        ++headers;
        std::ifstream in(e.path());
        std::string line;
        for (int n = 1; std::getline(in, line); ++n) {
            std::smatch m;
            if (std::regex_search(line, m, demo))
                found += e.path().filename().string() + ":" + std::to_string(n) + ": \"" + m.str() + "\"\n";
        }
    }
    INFO(found);
    CHECK(headers >= 5);  // pass, declare, gl, scene_view, shader at least
    CHECK(found.empty());
    fs::remove_all(prefix);
}
