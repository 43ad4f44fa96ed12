// "extends": a pipeline written as its changes to another — passes added, replaced,
// removed, moved or re-parameterised — with errors that name the file of the chain
// they are in. The files live in a map, read through the same reader interface the
// runtime gives a file system.
#include <catch2/catch.hpp>

#include <map>

#include "graph/compiler.hpp"
#include "graph/pipeline.hpp"

using namespace kiln;
using namespace kiln::graph;

namespace {

struct Files {
    std::map<std::string, std::string> text;
    PipelineReader reader() const {
        return [this](const std::string& file, std::string& out, std::string& why) {
            auto it = text.find(file);
            if (it == text.end()) {
                why = "cannot read the pipeline file";
                return false;
            }
            out = it->second;
            return true;
        };
    }
    Result<PipelineDesc> load(const std::string& file, std::vector<std::string>* chain = nullptr) const {
        Result<PipelineDesc> parsed = parsePipeline(text.at(file), file);
        if (!parsed) return parsed;
        return resolveExtends(std::move(*parsed), reader(), chain);
    }
};

const char* kBase = R"({
  "output": "c.color",
  "passes": [
    { "id": "a", "module": "ma", "params": { "size": 512, "mode": "x" } },
    { "id": "b", "module": "mb", "inputs": { "in": "a.out" } },
    { "id": "c", "module": "mc", "inputs": { "in": "b.out", "side": "a.out" }, "params": { "gain": 1.0 } }
  ]
})";

std::vector<std::string> ids(const PipelineDesc& d) {
    std::vector<std::string> out;
    for (const PassDesc& p : d.passes) out.push_back(p.id);
    return out;
}

const ParamLiteral* param(const PassDesc& p, const std::string& name) {
    for (const auto& [n, v] : p.params)
        if (n == name) return &v;
    return nullptr;
}

}  // namespace

TEST_CASE("a pipeline that extends another changes only what it names", "[extends]") {
    Files files;
    files.text["/p/base.json"] = kBase;
    files.text["/p/sub/child.json"] = R"({
      "extends": "../base.json",
      "output": "v.color",
      "passes": [
        { "id": "a", "params": { "size": 1024 } },
        { "id": "b", "remove": true },
        { "id": "c", "inputs": { "in": "a.out", "side": null }, "params": { "gain": null, "bias": 2 }, "enabled": false },
        { "id": "v", "module": "vignette", "inputs": { "color": "c.color" }, "after": "a" }
      ]
    })";
    std::vector<std::string> chain;
    Result<PipelineDesc> r = files.load("/p/sub/child.json", &chain);
    INFO(r.errorText());
    REQUIRE(r);
    CHECK(chain == std::vector<std::string>{"/p/sub/child.json", "/p/base.json"});
    CHECK(r->fileName == "/p/sub/child.json");
    CHECK(r->output == "v.color");
    CHECK(ids(*r) == std::vector<std::string>{"a", "v", "c"});
    const PassDesc& a = r->passes[0];
    CHECK(a.module == "ma");                   // kept from the base
    CHECK(param(a, "size")->i == 1024);        // set over it
    CHECK(param(a, "mode")->s == "x");         // untouched
    const PassDesc& c = r->passes[2];
    CHECK(!c.enabled);
    CHECK(c.inputs == std::vector<std::pair<std::string, std::string>>{{"in", "a.out"}});
    CHECK(param(c, "gain") == nullptr);  // null: back to the module's default
    CHECK(param(c, "bias")->i == 2);
    CHECK(r->passes[1].module == "vignette");
}

TEST_CASE("extends: a pass replaced whole, moved before another, and chains of three", "[extends]") {
    Files files;
    files.text["/p/base.json"] = kBase;
    files.text["/p/mid.json"] = R"({ "extends": "base.json",
      "passes": [ { "id": "b", "module": "other", "params": { "k": 2 } } ] })";
    files.text["/p/top.json"] = R"({ "extends": "mid.json",
      "passes": [ { "id": "c", "before": "a" }, { "id": "b", "params": { "k": 3 } } ] })";
    std::vector<std::string> chain;
    Result<PipelineDesc> r = files.load("/p/top.json", &chain);
    INFO(r.errorText());
    REQUIRE(r);
    CHECK(chain.size() == 3);
    CHECK(ids(*r) == std::vector<std::string>{"c", "a", "b"});
    CHECK(r->passes[2].module == "other");
    CHECK(r->passes[2].inputs.empty());  // replaced whole: the base's binding is gone
    CHECK(param(r->passes[2], "k")->i == 3);
    CHECK(r->output == "c.color");  // inherited
}

TEST_CASE("extends: mistakes name the file of the chain they are in", "[extends]") {
    Files files;
    files.text["/p/base.json"] = kBase;
    auto errorOf = [&](const std::string& child) {
        files.text["/p/child.json"] = child;
        Result<PipelineDesc> r = files.load("/p/child.json");
        REQUIRE(!r);
        return r.errorText();
    };
    CHECK_THAT(errorOf(R"({"extends": "none.json", "passes": []})"),
               Catch::Contains("/p/child.json: extends: /p/none.json: cannot read the pipeline file"));
    CHECK_THAT(errorOf(R"({"extends": "base.json", "passes": [{"id": "bb", "remove": true}]})"),
               Catch::Contains("/p/child.json: passes[0].remove: no pass \"bb\" to remove") && Catch::Contains("did you mean \"b\""));
    CHECK_THAT(errorOf(R"({"extends": "base.json", "passes": [{"id": "z", "params": {"k": 1}}]})"),
               Catch::Contains("passes[0]: no pass \"z\"") && Catch::Contains("names its \"module\""));
    CHECK_THAT(errorOf(R"({"extends": "base.json", "passes": [{"id": "z", "module": "m", "after": "q"}]})"),
               Catch::Contains("passes[0].after: no pass \"q\""));
    CHECK_THAT(errorOf(R"({"passes": [{"id": "z", "module": "m", "after": "a"}]})"),
               Catch::Contains("passes[0].after: \"after\" changes the pipeline this one extends"));
    CHECK_THAT(errorOf(R"({"passes": [{"id": "z"}]})"), Catch::Contains("missing \"module\""));
    CHECK_THAT(errorOf(R"({"passes": [{"id": "z", "module": "m", "inputs": {"in": null}}]})"),
               Catch::Contains("passes[0].inputs.in: null unbinds an input of the pipeline this one extends"));
    // An error inside the base is the base's, with its own place.
    files.text["/p/broken.json"] = R"({"passes": [{"id": "a", "modul": "ma"}]})";
    CHECK_THAT(errorOf(R"({"extends": "broken.json", "passes": []})"),
               Catch::Contains("/p/broken.json: passes[0].modul: unknown key"));
    // A cycle, through two files.
    files.text["/p/loop.json"] = R"({"extends": "child.json", "passes": []})";
    CHECK_THAT(errorOf(R"({"extends": "loop.json", "passes": []})"), Catch::Contains("a cycle"));
}

TEST_CASE("extends: the compiler's errors name the file and the entry that wrote the pass", "[extends]") {
    Files files;
    files.text["/p/base.json"] = kBase;
    files.text["/p/child.json"] = R"({ "extends": "base.json",
      "passes": [ { "id": "x", "module": "mx" }, { "id": "c", "params": { "gain": "loud" } } ] })";
    Result<PipelineDesc> r = files.load("/p/child.json");
    REQUIRE(r);
    CompileOptions opt;
    opt.resolve = [](const std::string&) {
        PassDeclaration d;
        d.input({.name = "in", .required = false});
        d.output({.name = "out"});
        d.output({.name = "color"});
        d.param(floatParam("gain", 1.0f, 0.0, 4.0));
        d.param(intParam("size", 1, 1, 4096));
        d.param(enumParam("mode", "x", {"x", "y"}));
        return Result<PassDeclaration>(d);
    };
    Result<Plan> plan = compile(*r, opt);
    REQUIRE(!plan);
    // "c" now sits at index 2 of the merged list; its bad value was written in the
    // child's passes[1].
    CHECK_THAT(plan.errorText(), Catch::Contains("/p/child.json: passes[1].params.gain"));
}
