// The pass SDK describes a scene model, not one scene: no header a pass author gets from
// an installation names the demo's objects. The headers are the installed ones, so a
// header added to the SDK is checked without this test knowing of it.
#include <catch2/catch.hpp>

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <regex>
#include <set>
#include <string>

#include "support/run_kiln.hpp"

namespace fs = std::filesystem;

namespace {

// This build installed into a prefix of its own (the test's earlier ones removed).
fs::path installedSdk(const std::string& name) {
    const fs::path prefix = fs::path(TEST_OUTPUT_DIR) / (name + "-" + std::to_string(getpid()));
    kiln::test::removeEarlierRuns(prefix);
    auto install = kiln::test::runProgram(CMAKE_COMMAND, "--install '" + std::string(KILN_BUILD_DIR) + "' --prefix '" +
                                                             prefix.string() + "'", 600);
    INFO(install.out << install.err);
    REQUIRE(install.exitCode == 0);
    return prefix;
}

}  // namespace

TEST_CASE("the installed SDK headers name no object of the demo scene", "[sdk]") {
    const fs::path prefix = installedSdk("names");
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

TEST_CASE("the SDK is one directory: what installs is what an in-tree pass can include", "[sdk]") {
    const fs::path prefix = installedSdk("sdk-list");
    auto headersIn = [](const fs::path& dir) {
        std::set<std::string> names;
        for (const fs::directory_entry& e : fs::directory_iterator(dir))
            if (e.path().extension() == ".hpp") names.insert(e.path().filename().string());
        return names;
    };
    const std::set<std::string> sdk = headersIn(fs::path(KILN_SOURCE_DIR) / "host/include/kiln");
    CHECK(headersIn(prefix / "include/kiln") == sdk);
    // The host's own headers are elsewhere, none of them in the SDK's directory.
    for (const std::string& hostOnly : headersIn(fs::path(KILN_SOURCE_DIR) / "host/core/include/kiln")) {
        INFO(hostOnly);
        CHECK(sdk.count(hostOnly) == 0);
    }
    // An in-tree pass builds with the SDK's include path only: none includes a host header.
    for (const fs::directory_entry& e : fs::recursive_directory_iterator(fs::path(KILN_SOURCE_DIR) / "passes")) {
        if (e.path().extension() != ".cpp" && e.path().extension() != ".hpp") continue;
        std::ifstream in(e.path());
        for (std::string line; std::getline(in, line);) {
            std::smatch m;
            static const std::regex include(R"(#include\s*[<"]kiln/([a-z_]+\.hpp)[>"])");
            if (std::regex_search(line, m, include)) {
                INFO(e.path().string() << ": " << line);
                CHECK(sdk.count(m[1].str()) == 1);
            }
        }
    }
    fs::remove_all(prefix);
}
