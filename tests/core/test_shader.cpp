#include <catch2/catch.hpp>

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>

#include "kiln/shader.hpp"
#include "run/program_cache.hpp"
#include "support/headless.hpp"

using namespace kiln;
namespace fs = std::filesystem;

namespace {
ShaderLibrary library() { return ShaderLibrary({TEST_SHADER_DIR}); }
}  // namespace

TEST_CASE("shader includes: nested, relative to the including file, each once", "[shader]") {
    PreprocessedSource src;
    ShaderError err;
    REQUIRE(library().preprocess("nested.frag", {{"FOO", "1"}}, src, err));
    CHECK(src.dependencies.size() == 3);
    // The define lands after #version, before any code.
    CHECK(src.text.find("#version 450 core\n#define FOO 1\n") == 0);
    CHECK(src.text.find("vec3 b()") < src.text.find("vec3 a()"));
    CHECK(src.files == std::vector<std::string>{"shaders/nested.frag", "shaders/inc/a.glsl", "shaders/inc/b.glsl"});
}

TEST_CASE("shader includes: a cycle is an error naming the chain", "[shader]") {
    PreprocessedSource src;
    ShaderError err;
    REQUIRE_FALSE(library().preprocess("cycle.frag", {}, src, err));
    CHECK_THAT(err.message, Catch::Contains("#include cycle"));
    CHECK_THAT(err.message,
               Catch::Contains("shaders/inc/cycle_1.glsl -> shaders/inc/cycle_2.glsl -> shaders/inc/cycle_1.glsl"));
}

TEST_CASE("shader includes: a missing include names the including file and line", "[shader]") {
    PreprocessedSource src;
    ShaderError err;
    REQUIRE_FALSE(library().preprocess("missing_include.frag", {}, src, err));
    CHECK(err.toString() == "shaders/missing_include.frag:2: #include \"inc/missing.glsl\": file not found in the shader roots");
}

TEST_CASE("shader includes: a path leaving the shader roots is refused", "[shader]") {
    PreprocessedSource src;
    ShaderError err;
    REQUIRE_FALSE(library().preprocess("escape.frag", {}, src, err));
    CHECK_THAT(err.toString(), Catch::Contains("escape.frag:2"));
    CHECK(library().resolve("../test_shader.cpp").empty());
}

TEST_CASE("mapInfoLog maps Mesa's and NVIDIA's formats through the line table", "[shader]") {
    PreprocessedSource src;
    ShaderError err;
    REQUIRE(library().preprocess("nested.frag", {{"A", "1"}, {"B", "2"}}, src, err));
    // Expanded: #version, 2 defines, a.glsl:1, b.glsl:1, a.glsl:3, ...
    REQUIRE(src.lines.size() > 5);
    auto e = mapInfoLog("0:5(5): error: `x' undeclared\n0(6) : error C1008: undefined variable\nlink trouble\n", src);
    REQUIRE(e.size() == 3);
    CHECK(e[0].toString() == "shaders/inc/b.glsl:1: error: `x' undeclared");
    CHECK(e[1].toString() == "shaders/inc/a.glsl:3: error C1008: undefined variable");
    CHECK(e[2].line == 0);
}

TEST_CASE("a compile error inside an included file points at that file and line", "[shader][gl]") {
    REQUIRE(test::ensureHeadlessContext());
    ProgramBuild b = buildProgram(library(), {{"error_in_include.frag"}, {}, "test"});
    REQUIRE_FALSE(b.ok());
    REQUIRE_FALSE(b.errors.empty());
    CHECK(b.errors[0].file == "shaders/inc/broken.glsl");
    CHECK(b.errors[0].line == 4);
    CHECK_THAT(b.errors[0].message, Catch::Contains("undefined_symbol"));
}

TEST_CASE("a compile error in the main file keeps its own line numbers after includes", "[shader][gl]") {
    REQUIRE(test::ensureHeadlessContext());
    ProgramBuild b = buildProgram(library(), {{"error_in_main.frag"}, {}, "test"});
    REQUIRE_FALSE(b.ok());
    CHECK(b.errors[0].file == "shaders/error_in_main.frag");
    CHECK(b.errors[0].line == 5);  // the undeclared name is on line 5
}

TEST_CASE("a valid program with nested includes compiles and links", "[shader][gl]") {
    REQUIRE(test::ensureHeadlessContext());
    ProgramBuild b = buildProgram(ShaderLibrary({TEST_SHADER_DIR, KILN_SOURCE_DIR "/shaders"}),
                                  {{"common/fullscreen.vert", "nested.frag"}, {}, "test"});
    INFO(b.errorText());
    CHECK(b.ok());
    // common/fullscreen.vert and its fullscreen.glsl, nested.frag and its inc/a.glsl, inc/b.glsl.
    CHECK(b.dependencies.size() == 5);
}

// llvmpipe links these (32 image units); NVIDIA's driver refuses image unit 8 and up,
// which is how voxelize's ten accumulator images once failed there and nowhere here.
TEST_CASE("a program that uses more than OpenGL 4.5 guarantees links, with a warning naming the file",
          "[shader][gl]") {
    REQUIRE(test::ensureHeadlessContext());
    const ShaderLibrary lib({TEST_SHADER_DIR, KILN_SOURCE_DIR "/shaders"});
    auto build = [&](std::vector<std::string> stages) {
        ProgramBuild b = buildProgram(lib, {std::move(stages), {}, "portability"});
        INFO(b.errorText());
        REQUIRE(b.ok());
        return b;
    };
    auto text = [](const ProgramBuild& b) {
        std::string all;
        for (auto& issue : b.portability) all += issue.toString() + "\n";
        return all;
    };

    ProgramBuild unit9 = build({"portability/image_unit_9.comp"});
    INFO(text(unit9));
    REQUIRE(unit9.portability.size() == 1);
    // Where it is declared, as a compile error would say it.
    CHECK(unit9.portability[0].file == "shaders/portability/image_unit_9.comp");
    CHECK(unit9.portability[0].line == 5);
    CHECK_THAT(unit9.portability[0].message, Catch::Contains("'u_tenth' is bound to image unit 9") &&
                                                 Catch::Contains("guarantees 0-7 only (NVIDIA"));

    // Nine images: the ninth's unit (8) and the fragment stage's count, each named, and
    // attributed to the fragment shader, not the vertex shader listed first.
    ProgramBuild nine = build({"common/fullscreen.vert", "portability/nine_images.frag"});
    INFO(text(nine));
    REQUIRE(nine.portability.size() == 2);
    for (auto& issue : nine.portability) CHECK(issue.file == "shaders/portability/nine_images.frag");
    CHECK_THAT(text(nine), Catch::Contains("'u_images[8]' is bound to image unit 8"));
    CHECK_THAT(text(nine), Catch::Contains("uses 9 images; OpenGL 4.5 guarantees a fragment shader 8 only"));

    ProgramBuild storage8 = build({"portability/storage_binding_8.comp"});
    INFO(text(storage8));
    REQUIRE(storage8.portability.size() == 1);
    CHECK(storage8.portability[0].line == 4);
    CHECK_THAT(storage8.portability[0].message, Catch::Contains("storage block 'Counts' is bound to storage buffer binding 8"));

    // At the limit, not over it: nothing.
    CHECK(text(build({"portability/eight_images.comp"})).empty());
}

namespace {
// A derivative after a fragment shader's first `discard`, as "line: text" (empty when
// none): dFdx/dFdy/fwidth, or a texture() lookup, which takes its level of detail from
// derivatives. GLSL leaves them undefined once lanes of the 2x2 quad may have left:
// llvmpipe only masks a discarded lane and computes them right anyway, NVIDIA's driver
// does not (voxelize.frag's depth span did this, and the H200's voxels lost the steep
// parts of the tumblers' shells). Text only: a helper from an #include that takes a
// derivative is not followed.
std::vector<std::string> derivativesAfterDiscard(const std::string& source) {
    static const std::regex discard(R"(\bdiscard\b)");
    static const std::regex derivative(R"(\b(dFdx\w*|dFdy\w*|fwidth\w*|texture|textureOffset|textureProj)\s*\()");
    std::vector<std::string> found;
    std::istringstream lines(source);
    std::string line;
    bool discarded = false;
    for (int number = 1; std::getline(lines, line); ++number) {
        const std::string code = line.substr(0, line.find("//"));
        if (discarded && std::regex_search(code, derivative)) found.push_back(std::to_string(number) + ": " + line);
        discarded = discarded || std::regex_search(code, discard);
    }
    return found;
}
}  // namespace

TEST_CASE("no shipped fragment shader takes a derivative after it may discard", "[shader]") {
    // The check itself, on voxelize.frag's old order and its fixed one.
    const std::string before = "void main() {\n    if (outside) discard;\n    float z = v_world.y;\n"
                               "    float span = abs(dFdx(z)) + abs(dFdy(z));  // dFdx after discard\n}\n";
    const std::string after = "void main() {\n    float span = fwidth(v_world.y);\n    if (outside) discard;\n"
                              "    o = texelFetch(u_t, ivec2(0), 0) + textureLod(u_t, uv, 0.0);\n}\n";
    CHECK(derivativesAfterDiscard(before) == std::vector<std::string>{"4:     float span = abs(dFdx(z)) + abs(dFdy(z));  // dFdx after discard"});
    CHECK(derivativesAfterDiscard(after).empty());
    CHECK(derivativesAfterDiscard("if (a) discard;\nvec4 c = texture(u_wood, uv);\n").size() == 1);

    int fragmentShaders = 0;
    for (const auto& entry : fs::recursive_directory_iterator(fs::path(KILN_SOURCE_DIR) / "shaders")) {
        if (entry.path().extension() != ".frag") continue;
        std::ifstream in(entry.path());
        std::stringstream text;
        text << in.rdbuf();
        INFO(entry.path().string());
        CHECK(derivativesAfterDiscard(text.str()).empty());
        ++fragmentShaders;
    }
    CHECK(fragmentShaders >= 10);
}

TEST_CASE("program cache: bounded, least recently used goes, an evicted variant rebuilds", "[shader][gl]") {
    REQUIRE(test::ensureHeadlessContext());
    const ShaderLibrary lib = library();
    run::ProgramCache cache;
    std::string error;
    auto variant = [&](int i) {
        ProgramDesc d{.stages = {"nested.frag"}, .defines = {{"FOO", std::to_string(i)}}};
        return cache.get(lib, d, error);
    };
    const GLuint first = variant(0);
    REQUIRE(first != 0);
    // Keep variant 0 in use while 2 × the bound of others pass through (a slider over a
    // define): the cache never holds more than the bound, and variant 0 survives.
    for (int i = 1; i <= int(2 * run::ProgramCache::kMaxVariants); ++i) {
        REQUIRE(variant(i) != 0);
        REQUIRE(variant(0) == first);
        CHECK(cache.size() <= run::ProgramCache::kMaxVariants);
    }
    // Variant 1 was evicted long ago: asking again builds it anew (the generation moves,
    // so a pass that uses it runs again).
    const uint64_t generation = cache.generation();
    CHECK(variant(1) != 0);
    CHECK(cache.generation() == generation + 1);
    CHECK(variant(1) != 0);
    CHECK(cache.generation() == generation + 1);  // cached now
}

TEST_CASE("program cache: a shader edit that breaks two variants stands as one error, the last good programs kept",
          "[shader][gl]") {
    // gbuffer builds its shader twice (KILN_WOOD 0 and 1): one typo must read as one
    // error in the debug view, not one per variant.
    REQUIRE(test::ensureHeadlessContext());
    const fs::path root = fs::temp_directory_path() / ("kiln-variants-" + std::to_string(::getpid()));
    fs::create_directories(root);
    const fs::path file = root / "two.frag";
    auto write = [&](const char* body) {
        std::ofstream(file) << "#version 450 core\nout vec4 o;\nvoid main() {\n    o = vec4(float(VARIANT));\n" << body
                            << "}\n";
    };
    write("");
    const ShaderLibrary lib({root});
    run::ProgramCache cache;
    std::string error;
    const GLuint a = cache.get(lib, {.stages = {"two.frag"}, .defines = {{"VARIANT", "0"}}}, error);
    const GLuint b = cache.get(lib, {.stages = {"two.frag"}, .defines = {{"VARIANT", "1"}}}, error);
    REQUIRE(a != 0);
    REQUIRE(b != 0);
    REQUIRE(a != b);
    write("    o = mux(o);\n");
    CHECK(cache.reload(lib, {fs::canonical(file)}) == 0);
    const std::vector<std::string> standing = cache.standingErrors();
    REQUIRE(standing.size() == 1);
    CHECK(standing[0].find("two.frag:5") != std::string::npos);
    CHECK(cache.get(lib, {.stages = {"two.frag"}, .defines = {{"VARIANT", "0"}}}, error) == a);  // kept
    CHECK(cache.get(lib, {.stages = {"two.frag"}, .defines = {{"VARIANT", "1"}}}, error) == b);
    fs::remove_all(root);
}

TEST_CASE("shader lines of any length are parsed without recursion (regression: std::regex overflowed the stack)",
          "[shader][robust]") {
    const fs::path root = fs::temp_directory_path() / ("kiln-long-lines-" + std::to_string(::getpid()));
    fs::create_directories(root);
    const std::string huge(200000, 'x');
    std::ofstream(root / "long_include.frag") << "#version 450 core\n#include \"" << huge << "\"\nvoid main() {}\n";
    std::ofstream(root / "long_garbage.frag") << "#version 450 core\n#include " << huge << "\nvoid main() {}\n";
    std::ofstream(root / "long_version.frag") << "#version 450 core " << std::string(200000, ' ') << "\nvoid main() {}\n";
    const ShaderLibrary lib({root});
    PreprocessedSource src;
    ShaderError err;
    // A 200 000-character name is no file: a named error at the line, not a crash.
    REQUIRE_FALSE(lib.preprocess("long_include.frag", {}, src, err));
    CHECK(err.line == 2);
    CHECK_THAT(err.message, Catch::Contains("file not found in the shader roots"));
    REQUIRE_FALSE(lib.preprocess("long_garbage.frag", {}, src, err));
    CHECK(err.toString().find("long_garbage.frag:2: malformed #include") != std::string::npos);
    CHECK(lib.preprocess("long_version.frag", {}, src, err));
    // Compiler logs are parsed the same way: a long message line maps through the table.
    const std::string log = "0:2(1): error: " + huge + "\n";
    auto mapped = mapInfoLog(log, src);
    REQUIRE(mapped.size() == 1);
    CHECK(mapped[0].line == 2);
    CHECK(mapped[0].message.size() == huge.size() + 7);
    fs::remove_all(root);
}
