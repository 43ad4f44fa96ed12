// Bad input, class by class, through the kiln binary as a user runs it: every case must
// exit 1 with a "kiln: error:" line that names the file and what is wrong — never a
// signal, never a hang, never a GL error.
#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "support/faults.hpp"
#include "support/run_kiln.hpp"

namespace fs = std::filesystem;
using kiln::test::Run;
using kiln::test::runKiln;

namespace {

const fs::path kSource = KILN_SOURCE_DIR;

// A fresh directory for one case, with a copy of the shaders when asked.
fs::path sandbox(const std::string& name, bool withShaders = false) {
    const fs::path dir = fs::path(TEST_OUTPUT_DIR) / ("bad-" + name + "-" + std::to_string(getpid()));
    fs::remove_all(dir);
    fs::create_directories(dir);
    if (withShaders) fs::copy(kSource / "shaders", dir / "shaders", fs::copy_options::recursive);
    return dir;
}

void write(const fs::path& p, const std::string& bytes) {
    fs::create_directories(p.parent_path());
    std::ofstream(p, std::ios::binary | std::ios::trunc) << bytes;
}

std::string garbage(size_t n) {
    std::string s(n, '\0');
    uint32_t x = 2463534242u;
    for (auto& c : s) x ^= x << 13, x ^= x >> 17, x ^= x << 5, c = char(x);
    return s;
}

// Inserts `line` after the #version line of a shader.
void insertAfterVersion(const fs::path& shader, const std::string& line) {
    std::string text = kiln::test::slurp(shader);
    const size_t eol = text.find('\n');
    write(shader, text.substr(0, eol + 1) + line + "\n" + text.substr(eol + 1));
}

struct Case {
    std::string name;
    std::function<std::string(const fs::path& dir)> setup;  // returns the extra arguments
    std::string expect;                                      // in the "kiln: error:" line
    std::string environment = {};                            // "NAME=value" for the run
    std::string expectToo = {};                              // in the same line
};

void check(const Case& c) {
    const fs::path dir = sandbox(c.name, true);
    const std::string args = "--headless --size 24x24 --frames 2 --out " + (dir / "out.png").string() + " " + c.setup(dir);
    const std::string binary = c.environment.empty() ? KILN_BINARY : "env " + c.environment + " " + KILN_BINARY;
    const Run r = kiln::test::runProgram(binary, args, 60);
    INFO("case: " << c.name << "\nargs: " << args << "\nstderr:\n" << r.err);
    CHECK(r.exitCode == 1);  // not a signal (128+N), not a hang (124)
    const size_t at = r.err.find("kiln: error: ");
    REQUIRE(at != std::string::npos);
    const std::string line = r.err.substr(at, r.err.find('\n', at) - at);
    CHECK_THAT(line, Catch::Contains(c.expect));
    CHECK_THAT(line, Catch::Contains(c.expectToo));
    CHECK(line.size() < 400);
    CHECK(r.err.find("GL [") == std::string::npos);  // no GL error on the way
    // Every line says what it is, continuation lines of a shader's log included.
    std::istringstream lines(r.err);
    for (std::string l; std::getline(lines, l);)
        if (!l.empty()) CHECK_THAT(l, Catch::StartsWith("kiln: "));
    fs::remove_all(dir);
}

}  // namespace

TEST_CASE("bad command-line values", "[integration][cli][robust]") {
    for (const char* args : {"--size 0x0", "--size -5x5", "--size 100000x100000", "--size 12", "--size", "--frames -3",
                             "--frames", "--frames 1x", "--frames 4294967297", "--frames 2147483648", "--frames 99999999999999999999", "--bogus", "--pipeline", "--seed banana",
                             "--budget -1", "--budget fast", "--budget", "--ui-probe", "--watchdog -1", "--watchdog 86401",
                             "--watchdog 1.5", "--watch", "--watch --out w.png --no-live"}) {
        const Run r = runKiln(std::string("--headless ") + args, 60);
        INFO(args << "\n" << r.err);
        CHECK(r.exitCode == 2);  // a usage error: nothing ran
        CHECK_THAT(r.err, Catch::StartsWith("kiln: error: "));
        CHECK(std::count(r.err.begin(), r.err.end(), '\n') == 1);  // one line
    }
}

TEST_CASE("bad pipeline files", "[integration][robust]") {
    const std::vector<Case> cases = {
        {"pipeline-missing", [](const fs::path& d) { return "--pipeline " + (d / "none.json").string(); },
         "none.json: cannot read the pipeline file"},
        {"pipeline-directory", [](const fs::path& d) { return "--pipeline " + d.string(); }, "is a directory"},
        // Never-ending and oversized files are refused without reading them whole.
        {"pipeline-device", [](const fs::path&) { return std::string("--pipeline /dev/zero"); },
         "/dev/zero: is not a regular file (a device, a pipe or a socket), not a pipeline file"},
        {"pipeline-huge", [](const fs::path& d) {
             write(d / "h.json", std::string((16u << 20) + 1, ' ')); return "--pipeline " + (d / "h.json").string(); },
         "h.json: the pipeline file holds more than 16777216 bytes, the limit"},
        {"pipeline-garbage", [](const fs::path& d) { write(d / "g.json", garbage(4096)); return "--pipeline " + (d / "g.json").string(); },
         "g.json:1:1: syntax error"},
        {"pipeline-empty", [](const fs::path& d) { write(d / "e.json", ""); return "--pipeline " + (d / "e.json").string(); },
         "e.json:1:1: syntax error while parsing value - unexpected end of input"},
        {"pipeline-overflow", [](const fs::path& d) { write(d / "o.json", "[22E444"); return "--pipeline " + (d / "o.json").string(); },
         "o.json:1:2: number overflow"},
        {"pipeline-deep", [](const fs::path& d) {
             write(d / "n.json", "{\"note\": " + std::string(100000, '[') + std::string(100000, ']') + "}");
             return "--pipeline " + (d / "n.json").string(); },
         "n.json:1:"},
    };
    for (auto& c : cases) check(c);
}

TEST_CASE("bad scene files", "[integration][robust]") {
    auto scene = [](const std::string& file, const std::string& text) {
        return [file, text](const fs::path& d) { write(d / file, text); return "--scene " + (d / file).string(); };
    };
    std::string many = "{\"tumblers\": [], \"marbles\": [";
    for (int i = 0; i < 5000; ++i) many += (i ? "," : "") + std::string("{\"position\": [0, 0, 0]}");
    many += "]}";
    const std::vector<Case> cases = {
        {"scene-missing", [](const fs::path& d) { return "--scene " + (d / "none.json").string(); },
         "none.json: cannot read the scene file"},
        {"scene-directory", [](const fs::path& d) { return "--scene " + d.string(); }, "is a directory, not a scene file"},
        {"scene-device", [](const fs::path&) { return std::string("--scene /dev/zero"); },
         "/dev/zero: is not a regular file (a device, a pipe or a socket), not a scene file"},
        {"scene-huge", scene("h.json", std::string((16u << 20) + 1, ' ')),
         "h.json: the scene file holds more than 16777216 bytes, the limit"},
        {"scene-garbage", scene("g.json", garbage(4096)), "g.json: line 1, column 1: syntax error"},
        {"scene-overflow", scene("o.json", R"({"tumblers": [], "physics": {"dt": 1e999}})"),
         "o.json: physics.dt: line 1, column 36: number overflow parsing '1e999'"},
        {"scene-overflow-8-bytes", scene("p.json", "[22E444"), "p.json: [0]: line 1, column 2: number overflow"},
        {"scene-deep", scene("n.json", "{\"note\": " + std::string(100000, '[') + std::string(100000, ']') + "}"),
         "n.json: line 1, column 41: nested deeper than 32 levels"},
        {"scene-long-value", scene("l.json", R"({"tumblers": [], "physics": {"tumbler_mode": ")" + std::string(100000, 'x') + "\"}}"),
         "l.json: physics.tumbler_mode: expected one of"},
        {"scene-many-marbles", scene("m.json", many), "m.json: marbles: 5000 marbles, more than the limit of 1024"},
    };
    for (auto& c : cases) check(c);
}

TEST_CASE("bad shader roots", "[integration][robust]") {
    const std::vector<Case> cases = {
        {"shaders-missing", [](const fs::path& d) { return "--shaders " + (d / "none").string(); },
         "shader root without common/frame.glsl"},
        {"shaders-binary", [](const fs::path& d) {
             write(d / "shaders/composite/composite.frag", garbage(2048));
             return "--shaders " + (d / "shaders").string(); },
         "composite.frag"},
        {"shaders-cycle", [](const fs::path& d) {
             insertAfterVersion(d / "shaders/composite/composite.frag", "#include \"composite/composite.frag\"");
             return "--shaders " + (d / "shaders").string(); },
         "#include cycle"},
        {"shaders-escape", [](const fs::path& d) {
             insertAfterVersion(d / "shaders/composite/composite.frag", "#include \"../../../../../../etc/passwd\"");
             return "--shaders " + (d / "shaders").string(); },
         "file not found in the shader roots"},
        {"shaders-long-line", [](const fs::path& d) {
             insertAfterVersion(d / "shaders/composite/composite.frag", "#include \"" + std::string(60000, 'x') + "\"");
             return "--shaders " + (d / "shaders").string(); },
         "composite.frag:2: #include"},
    };
    for (auto& c : cases) check(c);
}

TEST_CASE("bad module directories", "[integration][robust]") {
    const std::string real = KILN_BUILD_MODULE_DIR;
    auto with = [&](const fs::path& d) { return "--modules " + (d / "m").string() + ":" + real; };
    const std::vector<Case> cases = {
        {"modules-missing", [](const fs::path& d) { return "--modules " + (d / "none").string(); },
         "no module \"gbuffer\""},
        {"modules-garbage", [&](const fs::path& d) { write(d / "m/libpass_gbuffer.so", garbage(8192)); return with(d); },
         "libpass_gbuffer.so: cannot load: not a 64-bit ELF shared library"},
        {"modules-empty", [&](const fs::path& d) { write(d / "m/libpass_gbuffer.so", ""); return with(d); },
         "libpass_gbuffer.so: cannot load: not a shared library (0 bytes"},
        {"modules-truncated", [&](const fs::path& d) {
             fs::create_directories(d / "m");
             fs::copy_file(fs::path(real) / "libpass_gbuffer.so", d / "m/libpass_gbuffer.so");
             fs::resize_file(d / "m/libpass_gbuffer.so", 4096);
             return with(d); },
         "libpass_gbuffer.so: cannot load: truncated"},
        // What a linker leaves mid-write: the right size and headers, a body of zeros.
        {"modules-torn", [&](const fs::path& d) {
             write(d / "m/libpass_gbuffer.so", kiln::test::tornLibrary(kiln::test::slurp(fs::path(real) / "libpass_gbuffer.so")));
             return with(d); },
         "libpass_gbuffer.so: cannot load: its dynamic section lacks the symbol tables"},
        {"modules-symlink-loop", [&](const fs::path& d) {
             fs::create_directories(d / "m");
             fs::create_symlink("libpass_gbuffer.so", d / "m/libpass_gbuffer.so");
             return "--modules " + (d / "m").string(); },
         "no module \"gbuffer\""},
    };
    for (auto& c : cases) check(c);
}

// A pass module with a bug in one of its entry points (tests/core/modules/faulty.cpp,
// the bug chosen by KILN_TEST_FAULT): one named error, exit 1, never a signal or a hang.
TEST_CASE("modules that crash, abort, throw or loop", "[integration][robust][guard]") {
    const std::string modules = "--modules " + std::string(TEST_MODULE_DIR) + ":" + KILN_BUILD_MODULE_DIR;
    auto setup = [&](const fs::path& d) {
        write(d / "faulty.json", R"({"output": "bad.color", "passes": [{"id": "bad", "module": "test_faulty"}]})");
        return modules + " --watchdog 1 --pipeline " + (d / "faulty.json").string();
    };
    const std::map<std::string, std::string> where = {
        {"static", "in its static initialisers or kiln_pass_module()"},
        {"entry", "in its static initialisers or kiln_pass_module()"},
        {"create", "in create()"}, {"declare", "in declare()"}, {"execute", "in execute()"}, {"destroy", "in destroy()"}};
    std::vector<std::pair<std::string, std::string>> faults;  // spec, expected fault
    for (auto& [entry, text] : where) {
        faults.push_back({"segv@" + entry, "SIGSEGV"});
        faults.push_back({"loop@" + entry, "no return after 1.0 s"});
    }
    faults.insert(faults.end(), {{"abort@execute", "SIGABRT"}, {"stack@execute", "SIGSEGV"},
                                 {"throw@execute", "exception of type int"}, {"throw@declare", "exception of type int"},
                                 {"throw@static", "SIGABRT"}, {"throw@entry", "an exception"}, {"abort@create", "SIGABRT"}});
    for (auto& [spec, fault] : faults) {
        const std::string entry = spec.substr(spec.find('@') + 1);
        check({"fault-" + spec.substr(0, spec.find('@')) + "-" + entry, setup, fault, "KILN_TEST_FAULT=" + spec,
               where.at(entry)});
    }
}
