// Reading pipeline files: syntax errors with line:col, shape errors with JSON paths,
// and writing a pipeline back.
#include "fake_modules.hpp"
#include "kiln/names.hpp"

#include <catch2/catch.hpp>

using namespace kiln;
using namespace kiln::graph;
using Catch::Matchers::Contains;

namespace {
std::string parseErrors(const std::string& text) {
    Result<PipelineDesc> r = parsePipeline(text, "pipelines/x.json");
    REQUIRE_FALSE(r.ok());
    return r.errorText();
}
}  // namespace

TEST_CASE("a pipeline file parses into a PipelineDesc", "[parse]") {
    Result<PipelineDesc> r = parsePipeline(test::kBasicPipeline, "pipelines/basic.json");
    REQUIRE(r.ok());
    const PipelineDesc& d = *r;
    CHECK(d.fileName == "pipelines/basic.json");
    CHECK(d.output == "composite.color");
    REQUIRE(d.passes.size() == 4);
    CHECK(d.passes[0].id == "gbuffer");
    CHECK(d.passes[0].enabled);
    CHECK(d.passes[1].params.size() == 1);
    CHECK(d.passes[1].params[0].first == "size");
    CHECK(d.passes[1].params[0].second.type == ParamLiteral::Type::Int);
    CHECK(d.passes[1].params[0].second.i == 2048);
    REQUIRE(d.passes[3].inputs.size() == 4);
    CHECK(d.passes[3].inputs[3] == std::pair<std::string, std::string>("shadow_map", "shadow.depth"));
    CHECK(d.find("bloom") == 2);
    CHECK(d.find("nope") == -1);
}

TEST_CASE("a JSON syntax error reports file:line:col", "[parse]") {
    const std::string text = "{\n  \"output\": \"a.b\",\n  \"passes\": [\n    { \"id\": \"x\" \"module\": \"y\" }\n  ]\n}\n";
    Result<PipelineDesc> r = parsePipeline(text, "pipelines/x.json");
    REQUIRE_FALSE(r.ok());
    REQUIRE(r.errors().size() == 1);
    const Diagnostic& d = r.errors()[0];
    CHECK(d.line == 4);
    CHECK(d.column == 17);  // the '"' of "module"
    CHECK_THAT(d.str(), Contains("pipelines/x.json:4:17: syntax error while parsing object"));
    CHECK_THAT(d.str(), !Contains("json.exception"));
}

TEST_CASE("syntax errors point at the offending token", "[parse]") {
    auto at = [](const std::string& text) {
        Result<PipelineDesc> r = parsePipeline(text, "p.json");
        REQUIRE_FALSE(r.ok());
        return std::to_string(r.errors()[0].line) + ":" + std::to_string(r.errors()[0].column);
    };
    CHECK(at("{\n  \"passes\": [ { \"id\": \"a\" }, ]\n}") == "2:30");   // trailing comma: the ']'
    CHECK(at("{\n  \"output\": 12x }") == "2:13");                          // bad literal
    CHECK(at("{ \"output\": \"a\\\"b\" \"passes\" }") == "1:20");            // after an escaped quote
    CHECK(at("{") == "1:2");                                                  // end of input
}

TEST_CASE("a comment gets a hint about note fields", "[parse]") {
    const std::string e = parseErrors("{\n  // the reference pipeline\n  \"passes\": []\n}");
    CHECK_THAT(e, Contains("pipelines/x.json:2:3:"));
    CHECK_THAT(e, Contains("comments are not JSON: put prose in a \"note\" field"));
}

TEST_CASE("lineColumn counts from 1", "[parse]") {
    int line = 0, col = 0;
    lineColumn("ab\ncd", 0, line, col);
    CHECK((line == 1 && col == 1));
    lineColumn("ab\ncd", 4, line, col);
    CHECK((line == 2 && col == 2));
}

TEST_CASE("unknown keys are errors with the nearest key, except note", "[parse]") {
    std::string e = parseErrors(R"({ "output": "a.b", "pases": [] })");
    CHECK_THAT(e, Contains("pipelines/x.json: pases: unknown key \"pases\" (did you mean \"passes\"?)"));
    e = parseErrors(R"({ "output": "a.b", "passes": [ { "id": "a", "module": "m", "enable": false, "note": "ok" } ] })");
    CHECK_THAT(e, Contains("passes[0].enable: unknown key \"enable\" (did you mean \"enabled\"?)"));
    CHECK_THAT(e, !Contains("note"));
}

TEST_CASE("values of the wrong JSON type are errors with their path", "[parse]") {
    const std::string e = parseErrors(R"({ "output": 3, "passes": [
        { "id": "a", "module": "m", "enabled": "yes", "params": [], "inputs": { "x": 1 } } ] })");
    CHECK_THAT(e, Contains("output: expected string, got int 3"));
    CHECK_THAT(e, Contains("passes[0].enabled: expected bool, got string \"yes\""));
    CHECK_THAT(e, Contains("passes[0].params: expected object, got array []"));
    CHECK_THAT(e, Contains("passes[0].inputs.x: an input binding is a string \"<pass id>.<output>\", got int 1"));
}

TEST_CASE("missing id, module and passes", "[parse]") {
    std::string e = parseErrors(R"({ "output": "a.b", "passes": [ { "module": "m" }, { "id": "b" }, 7 ] })");
    CHECK_THAT(e, Contains("passes[0]: missing \"id\""));
    CHECK_THAT(e, Contains("passes[1]: missing \"module\""));
    CHECK_THAT(e, Contains("passes[2]: a pass is an object"));
    e = parseErrors(R"({ "output": "a.b" })");
    CHECK_THAT(e, Contains("pipelines/x.json: missing \"passes\""));
    CHECK_THAT(parseErrors("[1, 2]"), Contains("a pipeline file is a JSON object"));
}

TEST_CASE("duplicate keys are reported with their path", "[parse]") {
    const std::string e = parseErrors(R"({ "output": "a.b", "passes": [
        { "id": "a", "module": "m" },
        { "id": "b", "module": "m", "params": { "x": 1 }, "params": { "y": 2 } } ] })");
    CHECK_THAT(e, Contains("passes[1].params: duplicate key"));
}

TEST_CASE("writePipeline round-trips", "[parse]") {
    Result<PipelineDesc> a = parsePipeline(test::kBasicPipeline, "p.json");
    REQUIRE(a.ok());
    a->passes[1].enabled = false;
    a->passes[1].params[0].second = ParamLiteral::of(ParamValue(4096));
    a->passes[3].params.emplace_back("pcf", ParamLiteral::of(ParamValue(false)));
    const std::string text = writePipeline(*a);
    Result<PipelineDesc> b = parsePipeline(text, "p.json");
    REQUIRE(b.ok());
    CHECK(b->output == a->output);
    CHECK(b->note == a->note);
    REQUIRE(b->passes.size() == a->passes.size());
    CHECK_FALSE(b->passes[1].enabled);
    CHECK(b->passes[1].params[0].second.i == 4096);
    CHECK(b->passes[3].params.back().first == "pcf");
    CHECK(b->passes[3].inputs == a->passes[3].inputs);
    CHECK(writePipeline(*b) == text);
    CHECK_THAT(text, Contains("\"tint\": [1, 0.9, 0.8]"));  // flat arrays on one line
}

TEST_CASE("parameter values written back use the shortest float form", "[parse]") {
    CHECK(ParamLiteral::of(ParamValue(0.9f)).text == "0.9");
    CHECK(ParamLiteral::of(ParamValue(Color3{0.1f, 1.0f, 0.25f})).text == "[0.1,1.0,0.25]");
    CHECK(ParamLiteral::of(ParamValue(std::string("aces"))).text == "\"aces\"");
    CHECK(ParamLiteral::of(ParamValue(7)).type == ParamLiteral::Type::Int);
}

TEST_CASE("edit distance and suggestions", "[suggest]") {
    CHECK(editDistance("shadow", "shadow") == 0);
    CHECK(editDistance("shadw", "shadow") == 1);
    CHECK(editDistance("sahdow", "shadow") == 1);  // transposition
    CHECK(editDistance("", "abc") == 3);
    CHECK(editDistance("Shadow", "shadow") == 0);
    const std::vector<std::string> names = {"gbuffer", "shadow", "composite", "bloom"};
    CHECK(nearestName("blom", names) == "bloom");
    CHECK(nearestName("xyz", names).empty());
    CHECK(suggestion("xyz", names, "passes") == " (passes: gbuffer, shadow, composite, bloom)");
    CHECK(suggestion("shadw", names) == " (did you mean \"shadow\"?)");
}

TEST_CASE("formats, kinds and fallbacks have names", "[declare]") {
    for (Format f : {Format::RGBA8, Format::RGBA16F, Format::RGBA32F, Format::RG16F, Format::R16F, Format::R32F,
                     Format::R11G11B10F, Format::R32UI, Format::Depth32F, Format::Depth24}) {
        Format back = Format::RGBA8;
        REQUIRE(parseFormat(toString(f), back));
        CHECK(back == f);
    }
    Format f = Format::RGBA8;
    CHECK(parseFormat("RGBA16F", f));
    CHECK(f == Format::RGBA16F);
    CHECK_FALSE(parseFormat("rgb8", f));
    CHECK(isDepthFormat(Format::Depth32F));
    CHECK(isDepthFormat(Format::Depth24));
    CHECK_FALSE(isDepthFormat(Format::R32F));
    CHECK(std::string(toString(TextureKind::Color3D)) == "color 3D");
    CHECK(std::string(toString(Fallback::FarDepth)) == "far_depth");
    CHECK(std::string(toString(ParamType::Enum)) == "enum");
}
