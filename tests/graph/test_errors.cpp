// One test per error class: every message names its JSON path (and the nearest name
// where there is one), printed as "file: path: message".
#include "fake_modules.hpp"

#include <catch2/catch.hpp>

using namespace kiln;
using namespace kiln::graph;
using namespace kiln::graph::test;
using Catch::Matchers::Contains;

namespace {

const char* kFile = "pipelines/x.json";

// Compiles `json`, requires failure, returns every diagnostic, one per line.
std::string errorsOf(const std::string& json, std::vector<std::string> requested = {}) {
    Result<Plan> r = compileText(json, kFile, fakeOptions(std::move(requested)));
    REQUIRE_FALSE(r.ok());
    return r.errorText();
}

// A valid four-pass pipeline with `composite`'s extra fields spliced in.
std::string withComposite(const std::string& inputs, const std::string& params = "{}",
                          const std::string& output = "composite.color") {
    return R"({ "output": ")" + output + R"(", "passes": [
      { "id": "gbuffer", "module": "gbuffer" },
      { "id": "shadow", "module": "shadow" },
      { "id": "bloom", "module": "bloom", "inputs": { "color": "gbuffer.albedo" } },
      { "id": "composite", "module": "composite", "inputs": )" + inputs + R"(, "params": )" + params + R"( } ] })";
}

const std::string kGoodInputs =
    R"({ "albedo": "gbuffer.albedo", "normal": "gbuffer.normal", "depth": "gbuffer.depth", "shadow_map": "shadow.depth" })";

std::string inputsWith(const std::string& slot, const std::string& binding) {
    std::string s = R"({ "albedo": "gbuffer.albedo", "normal": "gbuffer.normal", "depth": "gbuffer.depth")";
    if (slot == "albedo" || slot == "normal" || slot == "depth") {
        // replace the existing binding
        const std::string key = "\"" + slot + "\": \"";
        const size_t at = s.find(key) + key.size();
        s.replace(at, s.find('"', at) - at, binding);
        return s + " }";
    }
    return s + ", \"" + slot + "\": \"" + binding + "\" }";
}

}  // namespace

TEST_CASE("the helpers build a valid pipeline", "[errors]") {
    REQUIRE(compileText(withComposite(kGoodInputs), kFile, fakeOptions()).ok());
    REQUIRE(compileText(withComposite(inputsWith("shadow_map", "shadow.depth")), kFile, fakeOptions()).ok());
}

TEST_CASE("unknown module suggests the nearest available one", "[errors]") {
    const std::string e = errorsOf(R"({ "output": "gbuffer.albedo", "passes": [
        { "id": "gbuffer", "module": "gbuffer" }, { "id": "shadow", "module": "shadw" } ] })");
    CHECK_THAT(e, Contains("pipelines/x.json: passes[1].module: unknown module \"shadw\" (did you mean \"shadow\"?)"));
}

TEST_CASE("a module name with a path or suffix is refused", "[errors]") {
    const std::string e = errorsOf(R"({ "output": "gbuffer.albedo", "passes": [
        { "id": "gbuffer", "module": "gbuffer" }, { "id": "b", "module": "../passes/bloom.so" } ] })");
    CHECK_THAT(e, Contains("passes[1].module: bad module name \"../passes/bloom.so\""));
    CHECK_THAT(e, Contains("(did you mean \"bloom\"?)"));
}

TEST_CASE("a resolver failure is passed through", "[errors]") {
    const std::string e = errorsOf(R"({ "output": "gbuffer.albedo", "passes": [
        { "id": "gbuffer", "module": "gbuffer" }, { "id": "c", "module": "crashy" } ] })");
    CHECK_THAT(e, Contains("passes[1].module: module \"crashy\": dlopen failed: libpass_crashy.so: undefined symbol foo"));
}

TEST_CASE("duplicate id", "[errors]") {
    const std::string e = errorsOf(R"({ "output": "gbuffer.albedo", "passes": [
        { "id": "gbuffer", "module": "gbuffer" }, { "id": "shadow", "module": "shadow" },
        { "id": "gbuffer", "module": "gbuffer" } ] })");
    CHECK_THAT(e, Contains("passes[2].id: duplicate id \"gbuffer\" (first used by passes[0])"));
}

TEST_CASE("bad id", "[errors]") {
    const std::string e = errorsOf(R"({ "output": "gbuffer.albedo", "passes": [
        { "id": "gbuffer", "module": "gbuffer" }, { "id": "Shadow Map", "module": "shadow" } ] })");
    CHECK_THAT(e, Contains("passes[1].id: bad id \"Shadow Map\": ids must match [a-z0-9_]+ (at most 64 characters) (e.g. \"shadow_map\")"));
}

TEST_CASE("input bound to a missing pass suggests the nearest id", "[errors]") {
    const std::string e = errorsOf(withComposite(inputsWith("shadow_map", "shadw.depth")));
    CHECK_THAT(e, Contains("pipelines/x.json: passes[3].inputs.shadow_map: no pass \"shadw\" (did you mean \"shadow\"?)"));
}

TEST_CASE("input bound to a missing output suggests the nearest output", "[errors]") {
    const std::string e = errorsOf(withComposite(inputsWith("albedo", "gbuffer.albdo")));
    CHECK_THAT(e, Contains("passes[3].inputs.albedo: pass \"gbuffer\" (module gbuffer) has no output \"albdo\" "
                           "(did you mean \"albedo\"?)"));
}

TEST_CASE("input bound to an internal texture", "[errors]") {
    const std::string e = errorsOf(withComposite(inputsWith("bloom", "bloom.ping")));
    CHECK_THAT(e, Contains("passes[3].inputs.bloom: \"bloom.ping\" is internal to \"bloom\" and cannot be bound"));
}

TEST_CASE("malformed binding string", "[errors]") {
    std::string e = errorsOf(withComposite(inputsWith("albedo", "gbuffer")));
    CHECK_THAT(e, Contains("passes[3].inputs.albedo: malformed binding \"gbuffer\": expected \"<pass id>.<output>\" "
                           "(e.g. \"gbuffer.albedo\")"));
    e = errorsOf(withComposite(inputsWith("albedo", "gbuffer.albedo.x")));
    CHECK_THAT(e, Contains("passes[3].inputs.albedo: malformed binding \"gbuffer.albedo.x\""));
}

TEST_CASE("input reading a pass later in the file says to move it", "[errors]") {
    const std::string e = errorsOf(R"({ "output": "composite.color", "passes": [
        { "id": "gbuffer", "module": "gbuffer" },
        { "id": "composite", "module": "composite", "inputs": { "albedo": "gbuffer.albedo",
          "normal": "gbuffer.normal", "depth": "gbuffer.depth", "shadow_map": "shadow.depth" } },
        { "id": "shadow", "module": "shadow" } ] })");
    CHECK_THAT(e, Contains("passes[1].inputs.shadow_map: \"shadow.depth\" is produced later in the file: "
                           "move \"shadow\" (passes[2]) before \"composite\" (passes[1])"));
}

TEST_CASE("input bound to its own pass", "[errors]") {
    const std::string e = errorsOf(withComposite(inputsWith("bloom", "composite.color")));
    CHECK_THAT(e, Contains("passes[3].inputs.bloom: input bound to its own pass (\"composite.color\")"));
}

TEST_CASE("unknown input slot suggests the nearest slot", "[errors]") {
    const std::string e = errorsOf(withComposite(inputsWith("shadw_map", "shadow.depth")));
    CHECK_THAT(e, Contains("passes[3].inputs.shadw_map: module \"composite\" has no input \"shadw_map\" "
                           "(did you mean \"shadow_map\"?)"));
}

TEST_CASE("depth vs colour mismatch names both kinds", "[errors]") {
    const std::string e = errorsOf(withComposite(inputsWith("depth", "gbuffer.albedo")));
    CHECK_THAT(e, Contains("passes[3].inputs.depth: input \"depth\" expects a depth 2D texture, "
                           "but \"gbuffer.albedo\" is color 2D (rgba8)"));
}

TEST_CASE("2D vs 3D mismatch names both kinds", "[errors]") {
    const std::string e = errorsOf(R"({ "output": "gbuffer.albedo", "passes": [
        { "id": "gbuffer", "module": "gbuffer" },
        { "id": "gi", "module": "cone_trace", "inputs": { "voxels": "gbuffer.normal",
          "normal": "gbuffer.normal", "depth": "gbuffer.depth" } } ] })");
    CHECK_THAT(e, Contains("passes[1].inputs.voxels: input \"voxels\" expects a color 3D texture, "
                           "but \"gbuffer.normal\" is color 2D (rgba16f)"));
}

TEST_CASE("required input whose producer is disabled names who lost what", "[errors]") {
    const std::string e = errorsOf(R"({ "output": "composite.color", "passes": [
        { "id": "gbuffer", "module": "gbuffer", "enabled": false },
        { "id": "composite", "module": "composite", "inputs": { "albedo": "gbuffer.albedo",
          "normal": "gbuffer.normal", "depth": "gbuffer.depth" } } ] })");
    CHECK_THAT(e, Contains("passes[1].inputs.albedo: \"composite\" loses required input \"albedo\": its producer "
                           "\"gbuffer\" (passes[0], which writes gbuffer.albedo) is disabled"));
    CHECK_THAT(e, Contains("passes[1].inputs.depth: \"composite\" loses required input \"depth\""));
}

TEST_CASE("required input not bound", "[errors]") {
    const std::string e = errorsOf(withComposite(R"({ "albedo": "gbuffer.albedo", "normal": "gbuffer.normal" })"));
    CHECK_THAT(e, Contains("passes[3].inputs: required input \"depth\" (depth 2D) is not bound "
                           "(e.g. \"gbuffer.depth\", \"shadow.depth\")"));
}

TEST_CASE("graph output errors", "[errors]") {
    SECTION("missing") {
        const std::string e = errorsOf(R"({ "passes": [ { "id": "gbuffer", "module": "gbuffer" } ] })");
        CHECK_THAT(e, Contains("pipelines/x.json: output: missing graph output"));
    }
    SECTION("malformed") {
        CHECK_THAT(errorsOf(withComposite(kGoodInputs, "{}", "composite")),
                   Contains("output: malformed graph output \"composite\""));
    }
    SECTION("unknown pass") {
        CHECK_THAT(errorsOf(withComposite(kGoodInputs, "{}", "compsite.color")),
                   Contains("output: no pass \"compsite\" (did you mean \"composite\"?)"));
    }
    SECTION("unknown output") {
        CHECK_THAT(errorsOf(withComposite(kGoodInputs, "{}", "composite.colour")),
                   Contains("output: pass \"composite\" (module composite) has no output \"colour\" "
                            "(did you mean \"color\"?)"));
    }
    SECTION("not colour 2D") {
        CHECK_THAT(errorsOf(withComposite(kGoodInputs, "{}", "gbuffer.depth")),
                   Contains("output: graph output \"gbuffer.depth\" is depth 2D (depth32f); it must be a color 2D texture"));
    }
    SECTION("internal") {
        CHECK_THAT(errorsOf(withComposite(kGoodInputs, "{}", "bloom.ping")),
                   Contains("output: \"bloom.ping\" is internal to \"bloom\""));
    }
}

TEST_CASE("graph output produced by a disabled pass", "[errors]") {
    const std::string e = errorsOf(R"({ "output": "bloom.color", "passes": [
        { "id": "gbuffer", "module": "gbuffer" },
        { "id": "bloom", "module": "bloom", "enabled": false, "inputs": { "color": "gbuffer.albedo" } } ] })");
    CHECK_THAT(e, Contains("output: graph output \"bloom.color\" is produced by \"bloom\" (passes[1]), which is disabled"));
}

TEST_CASE("unknown parameter suggests the nearest one", "[errors]") {
    const std::string e = errorsOf(withComposite(kGoodInputs, R"({ "exposre": 2.0 })"));
    CHECK_THAT(e, Contains("passes[3].params.exposre: module \"composite\" has no parameter \"exposre\" "
                           "(did you mean \"exposure\"?)"));
}

TEST_CASE("wrong parameter type names expected and actual", "[errors]") {
    CHECK_THAT(errorsOf(withComposite(kGoodInputs, R"({ "exposure": "bright" })")),
               Contains("passes[3].params.exposure: expected float, got string \"bright\""));
    CHECK_THAT(errorsOf(withComposite(kGoodInputs, R"({ "pcf": 1 })")),
               Contains("passes[3].params.pcf: expected bool, got int 1"));
    CHECK_THAT(errorsOf(withComposite(kGoodInputs, R"({ "tint": [1, 0.5] })")),
               Contains("passes[3].params.tint: expected color [r, g, b] (three numbers), got [1,0.5]"));
    const std::string e = errorsOf(R"({ "output": "gbuffer.albedo", "passes": [
        { "id": "gbuffer", "module": "gbuffer" },
        { "id": "shadow", "module": "shadow", "params": { "size": 2048.0 } } ] })");
    CHECK_THAT(e, Contains("passes[1].params.size: expected int, got float 2048.0 (write it without a fraction: 2048)"));
}

TEST_CASE("parameter out of range names the range", "[errors]") {
    CHECK_THAT(errorsOf(withComposite(kGoodInputs, R"({ "exposure": 20 })")),
               Contains("passes[3].params.exposure: out of range: 20 is not in [0, 16]"));
    const std::string e = errorsOf(R"({ "output": "gbuffer.albedo", "passes": [
        { "id": "gbuffer", "module": "gbuffer" },
        { "id": "shadow", "module": "shadow", "params": { "size": 9000 } } ] })");
    CHECK_THAT(e, Contains("passes[1].params.size: out of range: 9000 is not in [16, 8192]"));
}

TEST_CASE("enum value not among the choices", "[errors]") {
    CHECK_THAT(errorsOf(withComposite(kGoodInputs, R"({ "tonemap": "acse" })")),
               Contains("passes[3].params.tonemap: \"acse\" is not one of \"aces\", \"reinhard\", \"none\" "
                        "(did you mean \"aces\"?)"));
}

TEST_CASE("int not among the allowed values", "[errors]") {
    const std::string e = errorsOf(R"({ "output": "gbuffer.albedo", "passes": [
        { "id": "gbuffer", "module": "gbuffer" },
        { "id": "shadow", "module": "shadow" },
        { "id": "voxels", "module": "voxelize", "inputs": { "shadow_map": "shadow.depth" },
          "params": { "resolution": 100 } } ] })");
    CHECK_THAT(e, Contains("passes[2].params.resolution: 100 is not one of the allowed values 32, 64, 128"));
}

TEST_CASE("output size from a bad parameter is reported against the module", "[errors]") {
    std::string e = errorsOf(R"({ "output": "b.color", "passes": [ { "id": "b", "module": "broken_decl" } ] })");
    CHECK_THAT(e, Contains("passes[0].module: module \"broken_decl\" declares output \"color\" takes its size from "
                           "unknown parameter \"sise\" (a bug in the module's declaration, not in this file)"));
    e = errorsOf(R"({ "output": "b.color", "passes": [ { "id": "b", "module": "float_size" } ] })");
    CHECK_THAT(e, Contains("passes[0].module: module \"float_size\" declares output \"color\" takes its size from "
                           "parameter \"size\", which is a float, not an int"));
    e = errorsOf(R"({ "output": "b.color", "passes": [ { "id": "b", "module": "float_divisor" } ] })");
    CHECK_THAT(e, Contains("module \"float_divisor\" declares output \"color\" takes its size from "
                           "parameter \"stride\", which is a float, not an int"));
    e = errorsOf(R"({ "output": "b.color", "passes": [ { "id": "b", "module": "capped_by_nothing" } ] })");
    CHECK_THAT(e, Contains("module \"capped_by_nothing\" declares output \"color\" takes its size from "
                           "unknown parameter \"cpa\""));
    e = errorsOf(R"({ "output": "b.color", "passes": [ { "id": "b", "module": "divided_volume" } ] })");
    CHECK_THAT(e, Contains("module \"divided_volume\" declares output \"color\" is 3D but sized relative to the (2D) output"));
    e = errorsOf(R"({ "output": "b.color", "passes": [ { "id": "b", "module": "produced_when_wrong" } ] })");
    CHECK_THAT(e, Contains("declares output \"color\" is produced when \"mode\" is \"slwo\", which is not one of its choices"));
    CHECK_THAT(e, Contains("declares output \"other\" is produced when \"scale\" has some values, but it is not an enum"));
    CHECK_THAT(e, Contains("declares output \"strip\" has 0 tiles (must be >= 1)"));
}

TEST_CASE("all errors are collected, in file order", "[errors]") {
    const std::string e = errorsOf(R"({ "output": "composite.colour", "passes": [
        { "id": "gbuffer", "module": "gbufer" },
        { "id": "shadow", "module": "shadow", "params": { "size": "big" } },
        { "id": "composite", "module": "composite", "inputs": { "albedo": "gbuffer.albedo",
          "normal": "gbuffer.normal", "depth": "gbuffer.depth", "shadow_map": "shadw.depth" } } ] })");
    const size_t output = e.find("output: pass \"composite\"");
    const size_t module = e.find("passes[0].module: unknown module \"gbufer\" (did you mean \"gbuffer\"?)");
    const size_t param = e.find("passes[1].params.size: expected int, got string \"big\"");
    const size_t input = e.find("passes[2].inputs.shadow_map: no pass \"shadw\"");
    REQUIRE(output != std::string::npos);
    REQUIRE(module != std::string::npos);
    REQUIRE(param != std::string::npos);
    REQUIRE(input != std::string::npos);
    CHECK(output < module);
    CHECK(module < param);
    CHECK(param < input);
}

TEST_CASE("problems inside a disabled pass are warnings", "[errors]") {
    Result<Plan> r = compileText(R"({ "output": "gbuffer.albedo", "passes": [
        { "id": "gbuffer", "module": "gbuffer" },
        { "id": "shadow", "module": "shadow", "enabled": false, "params": { "size": "big" } } ] })",
                                 kFile, fakeOptions());
    REQUIRE(r.ok());
    REQUIRE(r->warnings.size() == 1);
    CHECK(r->warnings[0].str() ==
          "pipelines/x.json: passes[1].params.size: warning: expected int, got string \"big\" (pass is disabled)");
}

// Regressions from fuzzing the parser (issue "nothing a user types kills Kiln"): each
// used to abort or overflow the stack; each must now be one located, bounded error.
TEST_CASE("a number beyond double range is a located error, not an abort", "[errors][robust]") {
    CHECK_THAT(errorsOf(withComposite("{}", R"({ "exposure": 1e999 })")),
               Contains("pipelines/x.json:5:") && Contains("number overflow parsing '1e999' (beyond the range of a double)"));
    CHECK_THAT(errorsOf(withComposite("{}", R"({ "exposure": -1e999 })")), Contains("number overflow"));
    // The fuzzer's 8-byte input.
    CHECK_THAT(errorsOf("[22E444"), Contains("pipelines/x.json:1:2: number overflow parsing '22E444'"));
}

TEST_CASE("nesting is bounded: 10^5-deep arrays give one located error, quickly", "[errors][robust]") {
    for (const char* key : {"note", "id", "params\": {\"exposure"}) {
        const std::string deep = std::string(100000, '[') + std::string(100000, ']');
        const std::string json = R"({ "output": "composite.color", "passes": [ { ")" + std::string(key) + R"(": )" +
                                 deep + (std::string(key).find('{') != std::string::npos ? "}" : "") + " } ] }";
        const std::string e = errorsOf(json);
        INFO(key);
        CHECK_THAT(e, Contains("nested deeper than 32 levels"));
        CHECK(e.size() < 200);
    }
    // 4 levels of pipeline + 27 = 31 are fine as JSON (the parameter is then the wrong
    // type, said briefly).
    const std::string ok = std::string(27, '[') + "1" + std::string(27, ']');
    const std::string e = errorsOf(withComposite("{}", R"({ "exposure": )" + ok + " }"));
    const size_t at = e.find("passes[3].params.exposure");
    REQUIRE(at != std::string::npos);
    const std::string line = e.substr(at, e.find('\n', at) - at);
    INFO(line);
    CHECK(line.size() < 200);  // the value is shown elided to 80 bytes
}

TEST_CASE("user text in messages is cut short: a megabyte id does not make a megabyte message", "[errors][robust]") {
    const std::string longId(1000000, 'A');
    const std::string e = errorsOf(R"({ "output": "composite.color", "passes": [ { "id": ")" + longId +
                                   R"(", "module": "gbuffer" } ] })");
    CHECK_THAT(e, Contains("bad id \"AAAA"));
    CHECK_THAT(e, Contains("…(+"));
    CHECK(e.size() < 2000);
}
