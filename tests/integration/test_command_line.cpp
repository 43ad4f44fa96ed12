// The command line's conventions, on every program: --help and --version run nothing,
// usage errors exit 2 with one line, a run failure exits 1, Ctrl+C 130; kiln's outputs
// follow their extension, a headless run with nothing to write is refused, and what the
// modules declare can be listed, described and set.
#include <catch2/catch.hpp>

#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "app/context.hpp"
#include "kiln/data_root.hpp"
#include "kiln/image_io.hpp"
#include "run/module_registry.hpp"
#include "support/headless.hpp"
#include "support/run_kiln.hpp"

namespace fs = std::filesystem;
using namespace kiln;
using kiln::test::Run;
using kiln::test::runKiln;
using kiln::test::runProgram;

namespace {

fs::path sandbox(const std::string& name) {
    const fs::path dir = fs::path(TEST_OUTPUT_DIR) / ("cli-" + name + "-" + std::to_string(getpid()));
    fs::remove_all(dir);
    fs::create_directories(dir);
    return dir;
}

size_t lines(const std::string& s) { return size_t(std::count(s.begin(), s.end(), '\n')); }

// A PFM as written by writePfm: "PF", size, a negative scale (little-endian), rows bottom first.
bool readPfm(const fs::path& file, FloatImage& img) {
    std::ifstream in(file, std::ios::binary);
    std::string magic;
    double scale = 0;
    in >> magic >> img.width >> img.height >> scale;
    in.get();  // the one whitespace byte before the data
    if (magic != "PF" || scale >= 0 || img.width < 1 || img.height < 1) return false;
    img.channels = 3;
    img.pixels.resize(size_t(img.width) * img.height * 3);
    in.read(reinterpret_cast<char*>(img.pixels.data()), std::streamsize(img.pixels.size() * sizeof(float)));
    return bool(in);
}

}  // namespace

TEST_CASE("every program: --help and --version print and run nothing, a misspelt option exits 2 with a suggestion",
          "[integration][cli]") {
    const fs::path bin = fs::path(KILN_BINARY).parent_path();
    for (const char* program : {"kiln", "kiln-bench-render", "kiln-bench-quality", "kiln-bench-live", "kiln-bench-scene",
                                "kiln-bench-skip", "kiln-bench-overhead", "kiln-soak", "kiln-sim"}) {
        INFO(program);
        if (!fs::exists(bin / program)) {
            WARN(program << " is not built (KILN_BENCH off)");
            continue;
        }
        const fs::path cwd = sandbox(std::string("help-") + program);
        const Run help = runProgram((bin / program).string(), "--help", 60, cwd.string());
        CHECK(help.exitCode == 0);
        CHECK_THAT(help.out, Catch::Contains("Usage: " + std::string(program)));
        CHECK(help.err.empty());
        CHECK(fs::is_empty(cwd));  // no bench-out/, no CSV: nothing ran
        const Run version = runProgram((bin / program).string(), "--version", 60, cwd.string());
        CHECK(version.exitCode == 0);
        CHECK(version.out == std::string(program) + " " KILN_VERSION " (pass ABI " + std::to_string(kPassAbiVersion) + ")\n");
        // kiln-sim's options belong to its subcommands: its misspelling is of one.
        const std::string misspelt = std::string(program) == "kiln-sim" ? "run --stepz 3" : "--helpp";
        const Run typo = runProgram((bin / program).string(), misspelt, 60, cwd.string());
        CHECK(typo.exitCode == 2);
        CHECK(lines(typo.err) == 1);
        CHECK_THAT(typo.err, Catch::StartsWith(std::string(program) + ": error: unknown option"));
        CHECK_THAT(typo.err, Catch::Contains("did you mean"));
        fs::remove_all(cwd);
    }
}

TEST_CASE("kiln refuses what would do nothing or write the wrong thing, before it renders", "[integration][cli]") {
    const fs::path dir = sandbox("refusals");
    const std::string out = (dir / "x.png").string();
    struct Row {
        std::string args, expect;
        int exitCode;
    };
    const std::vector<Row> rows = {
        {"--headless --size 16x16", "a headless run needs something to write", 2},
        {"--headless --size 16x16 --out " + (dir / "x.jpg").string(), "the format follows the extension", 2},
        {"--headless --size 16x16 --out " + (dir / "x").string(), "the format follows the extension", 2},
        {"--headless --size 16x16 --out " + out + " --screenshot s.png", "--screenshot is for the window", 2},
        {"--headless --size 16x16 --out " + out + " --budget 50", "--budget is for the window", 2},
        {"--headless --size 16x16 --out " + out + " --window 800x600", "--window is for the window", 2},
        {"--size 16x16 --out " + out, "--out is for --headless", 2},
        {"--headless --size 16x16 --set shadow.size", "expected PASS.PARAM=VALUE", 2},
        {"--headless --size 16x16 --out " + out + " --view composite.colr", "did you mean \"color\"", 1},
        {"--headless --size 16x16 --out /proc/kiln-none/x.png", "cannot create the directory /proc/kiln-none", 1},
        {"--headless --size 16x16 --stats --set shadw.size=512", "--set shadw.size=512: no pass \"shadw\"", 1},
        {"--headless --size 16x16 --stats --set shadow.sise=512", "no parameter \"sise\" (did you mean \"size\"?)", 1},
        {"--headless --size 16x16 --stats --set shadow.size=big", "--set shadow.size=big: expected int", 1},
    };
    for (const Row& row : rows) {
        INFO(row.args);
        const Run r = runKiln(row.args, 120);
        INFO(r.err);
        CHECK(r.exitCode == row.exitCode);
        CHECK_THAT(r.err, Catch::Contains("kiln: error: ") && Catch::Contains(row.expect));
        CHECK(r.err.find("settled") == std::string::npos);  // refused before the frames
        CHECK(r.out.empty());
    }
    CHECK(!fs::exists(out));
    fs::remove_all(dir);
}

TEST_CASE("kiln --out writes PNG, OpenEXR or PFM by the extension, into directories it creates, and --opt=value works",
          "[integration][cli]") {
    const fs::path dir = sandbox("formats");
    const fs::path nested = dir / "a/b";
    const std::string common = "--headless --paused --size=24x16 --frames=1 ";
    FloatImage png, exr, pfm;
    std::string error;
    for (const char* ext : {"png", "exr", "pfm"}) {
        const Run r = runKiln(common + "--out=" + (nested / (std::string("final.") + ext)).string());
        INFO(ext << ": " << r.err);
        REQUIRE(r.exitCode == 0);
    }
    REQUIRE(readPng((nested / "final.png").string(), png, error));
    REQUIRE(readExr((nested / "final.exr").string(), exr, error));
    REQUIRE(readPfm(nested / "final.pfm", pfm));
    for (const FloatImage* img : {&exr, &pfm}) {
        REQUIRE(img->width == 24);
        REQUIRE(img->height == 16);
    }
    // The three hold the same frame: the float files exactly alike, the PNG their value
    // rounded to 8 bits (half a step, 0.5/255, with float slack); rows in the same order.
    float worstFloat = 0.0f, worstPng = 0.0f;
    for (int y = 0; y < 16; ++y)
        for (int x = 0; x < 24; ++x)
            for (int c = 0; c < 3; ++c) {
                worstFloat = std::max(worstFloat, std::abs(exr.at(x, y)[c] - pfm.at(x, y)[c]));
                worstPng = std::max(worstPng, std::abs(std::clamp(exr.at(x, y)[c], 0.0f, 1.0f) - png.at(x, y)[c]));
            }
    CHECK(worstFloat == 0.0f);
    CHECK(worstPng <= 0.5f / 255.0f + 1e-6f);
    // A second, independent reader agrees (OpenImageIO).
    if (std::system("command -v oiiotool > /dev/null") == 0) {
        const Run same = runProgram("oiiotool", "--fail 0 " + (nested / "final.exr").string() + " --ch R,G,B " +
                                                    (nested / "final.pfm").string() + " --diff");
        INFO(same.out);
        CHECK(same.exitCode == 0);
    }
    fs::remove_all(dir);
}

TEST_CASE("kiln --set changes a parameter as the file would, and says where a wrong one came from", "[integration][cli]") {
    const fs::path dir = sandbox("set");
    const std::string common = "--headless --paused --size 24x24 --frames 1 --out ";
    const Run plain = runKiln(common + (dir / "plain.exr").string());
    const Run brighter = runKiln(common + (dir / "bright.exr").string() + " --set composite.exposure=4 --set shadow.size=512");
    INFO(plain.err << brighter.err);
    REQUIRE(plain.exitCode == 0);
    REQUIRE(brighter.exitCode == 0);
    FloatImage a, b;
    std::string error;
    REQUIRE(readExr((dir / "plain.exr").string(), a, error));
    REQUIRE(readExr((dir / "bright.exr").string(), b, error));
    double sumA = 0, sumB = 0;
    for (size_t i = 0; i < a.pixels.size(); i += 4) sumA += a.pixels[i] + a.pixels[i + 1] + a.pixels[i + 2];
    for (size_t i = 0; i < b.pixels.size(); i += 4) sumB += b.pixels[i] + b.pixels[i + 1] + b.pixels[i + 2];
    // Four times the exposure through the tonemap's shoulder: brighter (1.23× here), far
    // from 4×; the frames are deterministic, so any real change shows.
    CHECK(sumB > 1.1 * sumA);
    // The plan sizes the shadow map by the value given.
    const Run plan = runKiln("--headless --size 24x24 --plan --set shadow.size=512");
    CHECK(plan.exitCode == 0);
    CHECK_THAT(plan.out, Catch::Contains("depth depth32f 512² (size)"));
    fs::remove_all(dir);
}

TEST_CASE("Ctrl+C stops a headless run and exits 130", "[integration][cli]") {
    const fs::path dir = sandbox("interrupt");
    const fs::path out = dir / "w.png";
    // Started in the background, interrupted once its first image is written (a deadline
    // of a minute for that), and its exit status read back.
    const std::string script = std::string(KILN_BINARY) + " --headless --size 16x16 --watch --out " + out.string() +
                               " > /dev/null 2>&1 & pid=$!; for i in $(seq 600); do [ -s " + out.string() +
                               " ] && break; sleep 0.1; done; kill -INT $pid; wait $pid; echo $?";
    const Run r = runProgram("sh", "-c '" + script + "'", 120);
    INFO(r.err);
    CHECK(fs::exists(out));
    CHECK(r.out == "130\n");
    fs::remove_all(dir);
}

TEST_CASE("kiln --list-modules and --describe say what each module declares", "[integration][cli]") {
    const Run list = runKiln("--list-modules");
    INFO(list.err);
    REQUIRE(list.exitCode == 0);
    REQUIRE(test::ensureHeadlessContext());
    run::ModuleRegistry registry({shippedFiles().modules});
    const std::vector<std::string> modules = registry.loader().available();
    REQUIRE(modules.size() >= 10);
    for (const std::string& name : modules) {
        INFO(name);
        CHECK_THAT(list.out, Catch::Contains(name + " "));
        auto decl = registry.declaration(name);
        REQUIRE(decl);
        const Run described = runKiln("--describe " + name);
        REQUIRE(described.exitCode == 0);
        CHECK_THAT(described.out, Catch::StartsWith("## " + name + "\n"));
        for (const InputDecl& i : decl->inputs) CHECK_THAT(described.out, Catch::Contains("| `" + i.name + "` | " + toString(i.kind)));
        for (const TextureDecl& t : decl->outputs)
            CHECK_THAT(described.out, Catch::Contains("| `" + t.name + "` | " + toString(t.kind) + " | " + toString(t.format)));
        for (const ParamDecl& p : decl->params) {
            INFO(p.name);
            CHECK_THAT(described.out, Catch::Contains("| `" + p.name + "` | " + toString(p.type) + " | "));
            if (!p.doc.empty()) CHECK_THAT(described.out, Catch::Contains(p.doc.substr(0, p.doc.find('|'))));
        }
    }
    const Run unknown = runKiln("--describe shadw");
    CHECK(unknown.exitCode == 2);
    CHECK_THAT(unknown.err, Catch::Contains("did you mean \"shadow\""));
    // The parameter reference in docs/ is this command's output, so it cannot drift.
    const Run all = runKiln("--describe all");
    REQUIRE(all.exitCode == 0);
    const std::string reference = test::slurp(fs::path(KILN_SOURCE_DIR) / "docs/parameters.md");
    CHECK(all.out.size() == reference.size());
    CHECK((all.out == reference));  // regenerate: build/bin/kiln --describe all > docs/parameters.md
}

TEST_CASE("docs/command_line.md explains every option kiln --help lists", "[integration][cli]") {
    const Run help = runKiln("--help");
    REQUIRE(help.exitCode == 0);
    const std::string doc = test::slurp(fs::path(KILN_SOURCE_DIR) / "docs/command_line.md");
    std::istringstream lines(help.out);
    int options = 0;
    for (std::string line; std::getline(lines, line);) {
        // An option line: two spaces, then "--name" (or "-h,--help").
        const size_t at = line.find("--");
        if (line.rfind("  -", 0) != 0 || at == std::string::npos) continue;
        const std::string name = line.substr(at, line.find_first_of(" ,", at) - at);
        INFO(name);
        CHECK(doc.find("`" + name) != std::string::npos);
        ++options;
    }
    CHECK(options >= 25);
}
