// patchPipelineText(): the debug view's "write back" changes only the edited values in
// the file's text, byte for byte, and refuses (with a reason) what is not a value edit.
#include "graph/pipeline.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>

using namespace kiln;
using namespace kiln::graph;
using Catch::Matchers::Contains;
namespace fs = std::filesystem;

namespace {

std::string readFile(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

PipelineDesc parseOk(const std::string& text) {
    Result<PipelineDesc> r = parsePipeline(text, "pipelines/x.json");
    INFO(r.errorText());
    REQUIRE(r.ok());
    return *r;
}

// Same type, same value (floats compared exactly). The one exception is the documented
// one: an int read back where a float was edited, equal to it, was left as written.
bool sameValue(const ParamLiteral& a, const ParamLiteral& b) {
    if (a.type == ParamLiteral::Type::Int && b.type == ParamLiteral::Type::Float) return a.f == b.f;
    if (a.type != b.type) return false;
    switch (a.type) {
        case ParamLiteral::Type::Null: return true;
        case ParamLiteral::Type::Bool: return a.b == b.b;
        case ParamLiteral::Type::Int: return a.i == b.i;
        case ParamLiteral::Type::Float: return a.f == b.f;
        case ParamLiteral::Type::String: return a.s == b.s;
        case ParamLiteral::Type::Object: return a.text == b.text;
        case ParamLiteral::Type::Array:
            if (a.items.size() != b.items.size()) return false;
            for (size_t k = 0; k < a.items.size(); ++k)
                if (!sameValue(a.items[k], b.items[k])) return false;
            return true;
    }
    return false;
}

const ParamLiteral* param(const PassDesc& p, const std::string& name) {
    for (const auto& [n, v] : p.params)
        if (n == name) return &v;
    return nullptr;
}

// `text` parses to `edited`: same passes, ids, modules, inputs, and every pass's enabled
// flag and params (by name, strictly equal, none extra).
void checkDescribes(const std::string& text, const PipelineDesc& edited) {
    const PipelineDesc got = parseOk(text);
    CHECK(got.output == edited.output);
    CHECK(got.note == edited.note);
    REQUIRE(got.passes.size() == edited.passes.size());
    for (size_t i = 0; i < got.passes.size(); ++i) {
        const PassDesc& g = got.passes[i];
        const PassDesc& e = edited.passes[i];
        INFO("pass " << e.id);
        CHECK(g.id == e.id);
        CHECK(g.module == e.module);
        CHECK(g.inputs == e.inputs);
        CHECK(g.enabled == e.enabled);
        CHECK(g.params.size() == e.params.size());
        for (const auto& [name, value] : e.params) {
            INFO("param " << name << " = " << value.text);
            const ParamLiteral* v = param(g, name);
            REQUIRE(v);
            CHECK(sameValue(*v, value));
        }
    }
}

void setParam(PassDesc& p, const std::string& name, const ParamLiteral& value) {
    for (auto& [n, v] : p.params)
        if (n == name) {
            v = value;
            return;
        }
    p.params.emplace_back(name, value);
}

std::string patchOk(const std::string& original, const PipelineDesc& edited) {
    std::string error;
    std::optional<std::string> out = patchPipelineText(original, edited, error);
    INFO(error);
    REQUIRE(out);
    CHECK(error.empty());
    checkDescribes(*out, edited);
    return *out;
}

std::string patchFails(const std::string& original, const PipelineDesc& edited) {
    std::string error;
    std::optional<std::string> out = patchPipelineText(original, edited, error);
    CHECK_FALSE(out);
    CHECK_FALSE(error.empty());
    return error;
}

// Keys out of the usual order, one-liners, odd spacing, a tab, strings with escapes and
// brackets, a nested array.
const std::string kOdd =
    "{\"passes\" : [\n"
    "   {\"module\":\"shadow\",   \"params\":{\"size\":2048,\"bias\" :   0.005}, \"id\":\"shadow\"},\n"
    "      { \"inputs\": { \"shadow_map\" : \"shadow.depth\" }, \"id\": \"composite\",\"module\": \"composite\",\n"
    "        \"params\": {\n"
    "            \"exposure\":1.0,   \"tint\": [ 1, 0.9,0.8 ],\n"
    "\t\t\"label\": \"a \\\"quoted\\\" \\\\ ] } , name\"\n"
    "        }\n"
    "      }\n"
    " ],\n"
    " \"output\":\"composite.color\"}\n";

}  // namespace

TEST_CASE("writeback: with nothing changed the text comes back byte for byte", "[writeback]") {
    const PipelineDesc d = parseOk(kOdd);
    CHECK(patchOk(kOdd, d) == kOdd);
}

TEST_CASE("writeback: a changed float in an oddly formatted file changes exactly its bytes", "[writeback]") {
    PipelineDesc d = parseOk(kOdd);
    setParam(d.passes[0], "bias", ParamLiteral::of(0.01f));
    setParam(d.passes[1], "exposure", ParamLiteral::of(1.5f));
    const std::string expected =
        "{\"passes\" : [\n"
        "   {\"module\":\"shadow\",   \"params\":{\"size\":2048,\"bias\" :   0.01}, \"id\":\"shadow\"},\n"
        "      { \"inputs\": { \"shadow_map\" : \"shadow.depth\" }, \"id\": \"composite\",\"module\": \"composite\",\n"
        "        \"params\": {\n"
        "            \"exposure\":1.5,   \"tint\": [ 1, 0.9,0.8 ],\n"
        "\t\t\"label\": \"a \\\"quoted\\\" \\\\ ] } , name\"\n"
        "        }\n"
        "      }\n"
        " ],\n"
        " \"output\":\"composite.color\"}\n";
    CHECK(patchOk(kOdd, d) == expected);
}

TEST_CASE("writeback: a colour is replaced whole and written like writePipeline writes it", "[writeback]") {
    PipelineDesc d = parseOk(kOdd);
    // The same colour as floats (what the debug view holds) is not a change: [ 1, 0.9,0.8 ] stays.
    setParam(d.passes[1], "tint", ParamLiteral::of(Color3{1.0f, 0.9f, 0.8f}));
    CHECK(patchOk(kOdd, d) == kOdd);
    setParam(d.passes[1], "tint", ParamLiteral::of(Color3{1.0f, 0.5f, 0.25f}));
    std::string expected = kOdd;
    const std::string before = "[ 1, 0.9,0.8 ]";
    expected.replace(expected.find(before), before.size(), "[1.0, 0.5, 0.25]");
    CHECK(patchOk(kOdd, d) == expected);
}

TEST_CASE("writeback: escaped strings, escaped keys and nested arrays beside a value do not confuse the scanner",
          "[writeback]") {
    const std::string text =
        "{ \"output\": \"p.color\", \"passes\": [ { \"id\": \"p\", \"module\": \"m\", \"params\": {\n"
        "  \"s\": \"x\\\"}]\\\\\", \"nested\": [[1, [2, {\"k\": \"]\"}]], [], {}], \"\\u0074arget\": 2,\n"
        "  \"name\": \"\\u00e9t\\u00e9 \\ud83d\\ude00\", \"last\": [\"]\", \"[\", \"\\\"\"] } } ] }";
    PipelineDesc d = parseOk(text);
    REQUIRE(param(d.passes[0], "target"));
    setParam(d.passes[0], "target", ParamLiteral::of(3));
    setParam(d.passes[0], "name", ParamLiteral::of(std::string("a \"b\" \\ c\n")));
    const std::string expected =
        "{ \"output\": \"p.color\", \"passes\": [ { \"id\": \"p\", \"module\": \"m\", \"params\": {\n"
        "  \"s\": \"x\\\"}]\\\\\", \"nested\": [[1, [2, {\"k\": \"]\"}]], [], {}], \"\\u0074arget\": 3,\n"
        "  \"name\": \"a \\\"b\\\" \\\\ c\\n\", \"last\": [\"]\", \"[\", \"\\\"\"] } } ] }";
    CHECK(patchOk(text, d) == expected);
}

TEST_CASE("writeback: a new parameter is appended to an existing params object, spaced like its last key",
          "[writeback]") {
    SECTION("a one-line object stays one line") {
        const std::string text = "{\"output\": \"a.b\", \"passes\": [ { \"id\": \"a\", \"module\": \"m\", "
                                 "\"params\": { \"x\": 1 } } ]}";
        PipelineDesc d = parseOk(text);
        setParam(d.passes[0], "y", ParamLiteral::of(0.5f));
        setParam(d.passes[0], "z", ParamLiteral::of(std::string("q")));
        CHECK(patchOk(text, d) == "{\"output\": \"a.b\", \"passes\": [ { \"id\": \"a\", \"module\": \"m\", "
                                  "\"params\": { \"x\": 1, \"y\": 0.5, \"z\": \"q\" } } ]}");
    }
    SECTION("a multi-line object gets the new key on its own line, indented like the last one") {
        const std::string text =
            "{\n  \"output\": \"a.b\",\n  \"passes\": [\n    {\n      \"id\": \"a\",\n      \"module\": \"m\",\n"
            "      \"params\": {\n        \"x\": 1,\n        \"w\" :  [1, 2]\n      }\n    }\n  ]\n}\n";
        PipelineDesc d = parseOk(text);
        setParam(d.passes[0], "y", ParamLiteral::of(true));
        CHECK(patchOk(text, d) ==
              "{\n  \"output\": \"a.b\",\n  \"passes\": [\n    {\n      \"id\": \"a\",\n      \"module\": \"m\",\n"
              "      \"params\": {\n        \"x\": 1,\n        \"w\" :  [1, 2],\n        \"y\" :  true\n      }\n"
              "    }\n  ]\n}\n");
    }
    SECTION("CRLF line ends are kept") {
        const std::string text = "{\r\n \"output\": \"a.b\",\r\n \"passes\": [{\"id\": \"a\", \"module\": \"m\",\r\n"
                                 "   \"params\": {\r\n     \"x\": 1\r\n   }}]\r\n}\r\n";
        PipelineDesc d = parseOk(text);
        setParam(d.passes[0], "y", ParamLiteral::of(2));
        CHECK(patchOk(text, d) == "{\r\n \"output\": \"a.b\",\r\n \"passes\": [{\"id\": \"a\", \"module\": \"m\",\r\n"
                                  "   \"params\": {\r\n     \"x\": 1,\r\n     \"y\": 2\r\n   }}]\r\n}\r\n");
    }
    SECTION("an empty object gets a one-line body") {
        const std::string text = "{\"output\": \"a.b\", \"passes\": [ { \"id\": \"a\", \"module\": \"m\", "
                                 "\"params\": {\n} } ]}";
        PipelineDesc d = parseOk(text);
        setParam(d.passes[0], "y", ParamLiteral::of(7));
        CHECK(patchOk(text, d) == "{\"output\": \"a.b\", \"passes\": [ { \"id\": \"a\", \"module\": \"m\", "
                                  "\"params\": { \"y\": 7 } } ]}");
    }
}

TEST_CASE("writeback: a new parameter on a pass without params creates the object after module", "[writeback]") {
    SECTION("one-line pass") {
        const std::string text = "{\"output\": \"a.b\", \"passes\": [\n  { \"id\": \"a\", \"module\": \"m\" }\n]}";
        PipelineDesc d = parseOk(text);
        setParam(d.passes[0], "size", ParamLiteral::of(1024));
        setParam(d.passes[0], "k", ParamLiteral::of(0.25f));
        CHECK(patchOk(text, d) == "{\"output\": \"a.b\", \"passes\": [\n  { \"id\": \"a\", \"module\": \"m\", "
                                  "\"params\": { \"size\": 1024, \"k\": 0.25 } }\n]}");
    }
    SECTION("multi-line pass, module not last, a UTF-8 BOM before the text") {
        const std::string text = "\xEF\xBB\xBF{\n  \"output\": \"a.b\",\n  \"passes\": [\n    {\n      \"id\": \"a\",\n"
                                 "      \"module\":\"m\",\n      \"inputs\": { \"x\": \"b.c\" }\n    }\n  ]\n}\n";
        PipelineDesc d = parseOk(text);
        setParam(d.passes[0], "size", ParamLiteral::of(1024));
        CHECK(patchOk(text, d) == "\xEF\xBB\xBF{\n  \"output\": \"a.b\",\n  \"passes\": [\n    {\n      \"id\": \"a\",\n"
                                  "      \"module\":\"m\",\n      \"params\":{ \"size\":1024 },\n"
                                  "      \"inputs\": { \"x\": \"b.c\" }\n    }\n  ]\n}\n");
    }
    SECTION("compact file") {
        const std::string text = "{\"output\":\"a.b\",\"passes\":[{\"module\":\"m\",\"id\":\"a\"}]}";
        PipelineDesc d = parseOk(text);
        setParam(d.passes[0], "size", ParamLiteral::of(1));
        setParam(d.passes[0], "on", ParamLiteral::of(false));
        CHECK(patchOk(text, d) == "{\"output\":\"a.b\",\"passes\":[{\"module\":\"m\",\"params\":{\"size\":1,\"on\":false},"
                                  "\"id\":\"a\"}]}");
    }
}

TEST_CASE("writeback: enabled is toggled both ways and true is kept explicit", "[writeback]") {
    const std::string text = "{ \"output\": \"c.x\", \"passes\": [\n"
                             "  { \"id\": \"a\", \"module\": \"m\" },\n"
                             "  { \"id\": \"b\", \"enabled\": false, \"module\": \"m\" },\n"
                             "  {\n    \"id\": \"c\",\n    \"module\": \"m\",\n    \"enabled\":true\n  }\n] }";
    PipelineDesc d = parseOk(text);
    d.passes[0].enabled = false;
    d.passes[1].enabled = true;
    d.passes[2].enabled = false;
    const std::string toggled = patchOk(text, d);
    CHECK(toggled == "{ \"output\": \"c.x\", \"passes\": [\n"
                     "  { \"id\": \"a\", \"module\": \"m\", \"enabled\": false },\n"
                     "  { \"id\": \"b\", \"enabled\": true, \"module\": \"m\" },\n"
                     "  {\n    \"id\": \"c\",\n    \"module\": \"m\",\n    \"enabled\":false\n  }\n] }");
    // And back: the added key stays, now true.
    for (PassDesc& p : d.passes) p.enabled = !p.enabled;
    CHECK(patchOk(toggled, d) == "{ \"output\": \"c.x\", \"passes\": [\n"
                                 "  { \"id\": \"a\", \"module\": \"m\", \"enabled\": true },\n"
                                 "  { \"id\": \"b\", \"enabled\": false, \"module\": \"m\" },\n"
                                 "  {\n    \"id\": \"c\",\n    \"module\": \"m\",\n    \"enabled\":true\n  }\n] }");
}

TEST_CASE("writeback: several edits in one call, in one pass and across passes", "[writeback]") {
    const std::string text = "{\n"
                             "  \"output\": \"b.color\",\n"
                             "  \"passes\": [\n"
                             "    { \"id\": \"a\", \"module\": \"ma\" },\n"
                             "    {\n"
                             "      \"id\": \"b\",\n"
                             "      \"module\": \"mb\",\n"
                             "      \"inputs\": { \"in\": \"a.out\" },\n"
                             "      \"params\": { \"k\": 0.5, \"n\": 3 }\n"
                             "    }\n"
                             "  ]\n"
                             "}\n";
    PipelineDesc d = parseOk(text);
    d.passes[0].enabled = false;
    setParam(d.passes[0], "size", ParamLiteral::of(64));  // enabled and params both after "module"
    setParam(d.passes[1], "n", ParamLiteral::of(4));      // the last param changed ...
    setParam(d.passes[1], "mode", ParamLiteral::of(std::string("fast")));  // ... and one added after it
    setParam(d.passes[1], "k", ParamLiteral::of(0.75f));
    d.passes[1].enabled = false;
    CHECK(patchOk(text, d) == "{\n"
                              "  \"output\": \"b.color\",\n"
                              "  \"passes\": [\n"
                              "    { \"id\": \"a\", \"module\": \"ma\", \"enabled\": false, \"params\": { \"size\": 64 } },\n"
                              "    {\n"
                              "      \"id\": \"b\",\n"
                              "      \"module\": \"mb\",\n"
                              "      \"enabled\": false,\n"
                              "      \"inputs\": { \"in\": \"a.out\" },\n"
                              "      \"params\": { \"k\": 0.75, \"n\": 4, \"mode\": \"fast\" }\n"
                              "    }\n"
                              "  ]\n"
                              "}\n");
}

TEST_CASE("writeback: numbers are written the way writePipeline writes them", "[writeback]") {
    const std::string text = "{\"output\": \"a.b\", \"passes\": [{\"id\": \"a\", \"module\": \"m\", "
                             "\"params\": {\"f\": 1, \"g\": 2048.0, \"h\": 0.5}}]}";
    PipelineDesc d = parseOk(text);
    // An int in the file equal to the edited float is already right: a float param takes `1`.
    setParam(d.passes[0], "f", ParamLiteral::of(1.0f));
    // A float in the file where the edit is an int is rewritten: an int param refuses 2048.0.
    setParam(d.passes[0], "g", ParamLiteral::of(2048));
    // Floats in their shortest round-tripping form: 0.1f is 0.1, not 0.10000000149011612.
    setParam(d.passes[0], "h", ParamLiteral::of(0.1f));
    setParam(d.passes[0], "big", ParamLiteral::of(3.0e20f));
    setParam(d.passes[0], "whole", ParamLiteral::of(60.0f));
    std::string error;
    const std::optional<std::string> out = patchPipelineText(text, d, error);
    REQUIRE(out);
    CHECK(*out == "{\"output\": \"a.b\", \"passes\": [{\"id\": \"a\", \"module\": \"m\", "
                  "\"params\": {\"f\": 1, \"g\": 2048, \"h\": 0.1, \"big\": 3e+20, \"whole\": 60.0}}]}");
    // The numbers read back as written; `f` stays an int, which is why this is not checkDescribes().
    const PipelineDesc back = parseOk(*out);
    CHECK(param(back.passes[0], "f")->type == ParamLiteral::Type::Int);
    CHECK(param(back.passes[0], "g")->type == ParamLiteral::Type::Int);
    CHECK(param(back.passes[0], "h")->f == param(d.passes[0], "h")->f);
    CHECK(param(back.passes[0], "big")->f == param(d.passes[0], "big")->f);
    CHECK(param(back.passes[0], "whole")->type == ParamLiteral::Type::Float);
    CHECK(static_cast<float>(param(back.passes[0], "h")->f) == 0.1f);
}

TEST_CASE("writeback: what is not a value edit returns nothing and says why", "[writeback]") {
    const PipelineDesc base = parseOk(kOdd);
    SECTION("a pass removed") {
        PipelineDesc d = base;
        d.passes.pop_back();
        CHECK_THAT(patchFails(kOdd, d), Contains("passes"));
    }
    SECTION("passes reordered") {
        PipelineDesc d = base;
        std::swap(d.passes[0], d.passes[1]);
        CHECK_THAT(patchFails(kOdd, d), Contains("reordered"));
    }
    SECTION("a pass added") {
        PipelineDesc d = base;
        d.passes.push_back(d.passes[0]);
        d.passes.back().id = "shadow2";
        CHECK_THAT(patchFails(kOdd, d), Contains("passes"));
    }
    SECTION("an id changed") {
        PipelineDesc d = base;
        d.passes[0].id = "shadows";
        CHECK_THAT(patchFails(kOdd, d), Contains("\"shadows\""));
    }
    SECTION("a module changed") {
        PipelineDesc d = base;
        d.passes[1].module = "blur";
        CHECK_THAT(patchFails(kOdd, d), Contains("module"));
    }
    SECTION("an input changed") {
        PipelineDesc d = base;
        d.passes[1].inputs[0].second = "gbuffer.depth";
        CHECK_THAT(patchFails(kOdd, d), Contains("inputs"));
    }
    SECTION("the output changed") {
        PipelineDesc d = base;
        d.output = "shadow.depth";
        CHECK_THAT(patchFails(kOdd, d), Contains("output"));
    }
    SECTION("a note added") {
        PipelineDesc d = base;
        d.passes[0].note = "hello";
        CHECK_THAT(patchFails(kOdd, d), Contains("note"));
    }
    SECTION("a parameter removed") {
        PipelineDesc d = base;
        d.passes[0].params.erase(d.passes[0].params.begin());
        CHECK_THAT(patchFails(kOdd, d), Contains("\"size\""));
    }
    SECTION("a parameter named twice") {
        PipelineDesc d = base;
        d.passes[0].params.emplace_back("size", ParamLiteral::of(3));
        CHECK_THAT(patchFails(kOdd, d), Contains("twice"));
    }
    SECTION("a value JSON cannot hold") {
        PipelineDesc d = base;
        setParam(d.passes[0], "bias", ParamLiteral::of(std::numeric_limits<float>::quiet_NaN()));
        CHECK_THAT(patchFails(kOdd, d), Contains("finite"));
        d = base;
        ParamLiteral bad;  // not through ParamLiteral::of, which would throw on it
        bad.type = ParamLiteral::Type::String;
        bad.s = "\xff";
        setParam(d.passes[0], "tag", bad);
        CHECK_THAT(patchFails(kOdd, d), Contains("UTF-8"));
    }
    SECTION("an original that does not parse") {
        CHECK_THAT(patchFails("{ \"passes\": [ ", base), Contains("does not parse"));
    }
}

TEST_CASE("writeback: every shipped pipeline round-trips, unchanged and with one edit per pass", "[writeback][files]") {
    const fs::path dir = KILN_PIPELINE_DIR;
    REQUIRE(fs::is_directory(dir));
    int files = 0;
    for (const auto& entry : fs::directory_iterator(dir)) {
        const fs::path p = entry.path();
        if (p.extension() != ".json" || p.filename() == "pipeline.schema.json") continue;
        ++files;
        INFO(p.filename().string());
        const std::string text = readFile(p);
        const PipelineDesc base = parseOk(text);
        if (!base.extends.empty()) {  // partly another file's: refused, whatever the edit
            std::string why;
            CHECK(!patchPipelineText(text, base, why));
            CHECK_THAT(why, Contains("it extends " + base.extends));
            continue;
        }

        // No change: the same bytes.
        CHECK(patchOk(text, base) == text);

        // One parameter changed per pass (the first one; a pass without params gets one),
        // and every pass toggled.
        PipelineDesc d = base;
        for (PassDesc& pass : d.passes) {
            INFO(pass.id);
            pass.enabled = !pass.enabled;
            if (pass.params.empty()) {
                pass.params.emplace_back("added", ParamLiteral::of(0.375f));
                continue;
            }
            ParamLiteral& v = pass.params.front().second;
            switch (v.type) {
                case ParamLiteral::Type::Bool: v = ParamLiteral::of(!v.b); break;
                case ParamLiteral::Type::Int: v = ParamLiteral::of(static_cast<int>(v.i) + 1); break;
                case ParamLiteral::Type::Float: v = ParamLiteral::of(static_cast<float>(v.f) * 2.0f + 0.5f); break;
                case ParamLiteral::Type::String: v = ParamLiteral::of(v.s + "_x"); break;
                case ParamLiteral::Type::Array: v = ParamLiteral::of(Color3{0.25f, 0.5f, 0.75f}); break;
                default: FAIL("unexpected parameter type " << toString(v.type));
            }
        }
        const std::string patched = patchOk(text, d);
        CHECK(patched != text);
        // Only values changed: the file's structure tokens outside the passes are where they were.
        CHECK(patched.substr(0, text.find("\"passes\"")) == text.substr(0, text.find("\"passes\"")));

        // And back to the start: every value is the original one again (an added
        // "enabled" key or parameter stays, so the text may differ, the desc may not).
        PipelineDesc back = base;
        for (size_t i = 0; i < back.passes.size(); ++i)
            if (base.passes[i].params.empty()) back.passes[i].params = d.passes[i].params;
        patchOk(patched, back);
    }
    CHECK(files >= 4);
}
