// The Debian package (cpack -G DEB): its contents are the installed layout under /usr,
// its dependencies the Debian runtime packages the binaries link, and the files it holds
// run: unpacked (not installed) into a directory, its kiln renders from there.
#include <catch2/catch.hpp>

#include <unistd.h>

#include <filesystem>
#include <set>
#include <sstream>
#include <string>

#include "kiln/image_io.hpp"
#include "support/run_kiln.hpp"

namespace fs = std::filesystem;
using kiln::test::runProgram;

TEST_CASE("cpack -G DEB: the layout under /usr, Debian dependencies, and it runs unpacked", "[sdk]") {
    const fs::path base = fs::path(TEST_OUTPUT_DIR) / ("deb-" + std::to_string(getpid()));
    kiln::test::removeEarlierRuns(base);
    fs::create_directories(base);
    auto pack = runProgram(CPACK_COMMAND, "-G DEB --config '" + std::string(KILN_BUILD_DIR) + "/CPackConfig.cmake' -B '" +
                                              base.string() + "'", 900);
    INFO(pack.out << pack.err);
    REQUIRE(pack.exitCode == 0);
    fs::path deb;
    for (const auto& entry : fs::directory_iterator(base))
        if (entry.path().extension() == ".deb") deb = entry.path();
    REQUIRE(!deb.empty());
    CHECK(deb.filename().string().find("kiln_" KILN_VERSION) == 0);

    auto listing = runProgram("dpkg-deb", "--contents '" + deb.string() + "'");
    REQUIRE(listing.exitCode == 0);
    std::set<std::string> files;  // "./usr/bin/kiln", ...
    std::istringstream lines(listing.out);
    for (std::string line; std::getline(lines, line);)
        if (const size_t at = line.find(" ./"); at != std::string::npos) files.insert(line.substr(at + 1, line.find(" -> ") - at - 1));
    for (const char* file : {"./usr/bin/kiln", "./usr/bin/kiln-sim", "./usr/lib/libkiln_core.so", "./usr/lib/libkiln_sim.so",
                             "./usr/include/kiln/pass.hpp", "./usr/include/kiln/loader/glad/gl.h",
                             "./usr/share/kiln/pipelines/default.json", "./usr/share/kiln/shaders/common/fullscreen.vert",
                             "./usr/share/kiln/scenes/cornell.json", "./usr/lib/cmake/Kiln/KilnConfig.cmake",
                             "./usr/lib/cmake/Kiln/KilnModule.cmake", "./usr/share/man/man1/kiln.1"})
        CHECK(files.count(file) == 1);
    // Every pass folder of the tree ships its module; no test module or test program ships.
    for (const auto& entry : fs::directory_iterator(fs::path(KILN_SOURCE_DIR) / "passes"))
        if (entry.is_directory()) CHECK(files.count("./usr/lib/kiln/modules/libpass_" + entry.path().filename().string() + ".so") == 1);
    for (const std::string& file : files) {
        INFO(file);
        CHECK(file.find("test") == std::string::npos);
        CHECK((file.rfind("./usr/", 0) == 0 || file == "./"));
    }

    auto fields = runProgram("dpkg-deb", "--field '" + deb.string() + "' Depends");
    REQUIRE(fields.exitCode == 0);
    INFO(fields.out);
    for (const char* package : {"libc6", "libstdc++6", "libglfw3", "libegl1"}) CHECK(fields.out.find(package) != std::string::npos);

    // Unpacked anywhere, the package's own kiln finds its files next to it and renders.
    REQUIRE(runProgram("dpkg-deb", "--extract '" + deb.string() + "' '" + (base / "root").string() + "'").exitCode == 0);
    const std::string kiln = (base / "root/usr/bin/kiln").string();
    auto help = runProgram(kiln, "--help", 60, base.string());
    CHECK(help.out.find("the installation, " + (base / "root/usr/share/kiln").string()) != std::string::npos);
    auto render = runProgram(kiln, "--headless --size 32x32 --paused --out '" + (base / "deb.png").string() + "'", 300, base.string());
    INFO(render.err);
    REQUIRE(render.exitCode == 0);
    kiln::FloatImage image;
    std::string error;
    REQUIRE(kiln::readPng((base / "deb.png").string(), image, error));
    double sum = 0;
    for (float v : image.pixels) sum += v;
    CHECK(sum > 0.1 * image.width * image.height);  // a lit box, not a black or missing frame
}
