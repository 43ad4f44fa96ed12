// Plans: culling, fallbacks, order, parameters, sizes, printing, signatures, diffs.
#include "fake_modules.hpp"

#include <catch2/catch.hpp>

#include <algorithm>

using namespace kiln;
using namespace kiln::graph;
using namespace kiln::graph::test;
using Catch::Matchers::Contains;

namespace {

Plan compileOk(const std::string& json, std::vector<std::string> requested = {}) {
    Result<Plan> r = compileText(json, "pipelines/basic.json", fakeOptions(std::move(requested)));
    INFO(r.errorText());
    REQUIRE(r.ok());
    return std::move(r.value());
}

const PlannedPass& pass(const Plan& p, const std::string& id) {
    const int i = p.find(id);
    REQUIRE(i >= 0);
    return p.passes[static_cast<size_t>(i)];
}

std::string replaced(std::string s, const std::string& from, const std::string& to) {
    const size_t at = s.find(from);
    REQUIRE(at != std::string::npos);
    return s.replace(at, from.size(), to);
}

}  // namespace

TEST_CASE("a valid pipeline compiles in file order", "[plan]") {
    const Plan p = compileOk(kBasicPipeline);
    REQUIRE(p.passes.size() == 4);
    CHECK(p.passes[0].id == "gbuffer");
    CHECK(p.passes[1].id == "shadow");
    CHECK(p.passes[2].id == "bloom");
    CHECK(p.passes[3].id == "composite");
    CHECK(p.runOrder() == std::vector<int>{0, 1, 3});
    CHECK(p.output.pass == 3);
    CHECK(p.output.name == "color");
    CHECK(p.warnings.empty());

    const PlannedPass& c = pass(p, "composite");
    REQUIRE(c.bindings.size() == 6);  // one per declared input, in declaration order
    CHECK(c.bindings[0].slot == "albedo");
    CHECK(c.bindings[0].producer == 0);
    CHECK(c.bindings[0].output == "albedo");
    CHECK(c.binding("shadow_map")->producer == 1);
    CHECK(c.binding("shadow_map")->output == "depth");
    CHECK_FALSE(c.binding("gi")->bound());  // optional, unbound: its fallback
    CHECK(c.binding("gi")->fallback == Fallback::Black);
    CHECK(c.binding("gi")->lost.empty());
}

TEST_CASE("file order is execution order, also when reordered", "[plan]") {
    // shadow moved after bloom: still valid, and the plan follows the file.
    const std::string moved = R"({ "output": "composite.color", "passes": [
        { "id": "gbuffer", "module": "gbuffer" },
        { "id": "bloom", "module": "bloom", "inputs": { "color": "gbuffer.albedo" } },
        { "id": "shadow", "module": "shadow" },
        { "id": "composite", "module": "composite", "inputs": { "albedo": "gbuffer.albedo",
          "normal": "gbuffer.normal", "depth": "gbuffer.depth", "shadow_map": "shadow.depth",
          "bloom": "bloom.color" } } ] })";
    const Plan p = compileOk(moved);
    std::vector<std::string> ids;
    for (int i : p.runOrder()) ids.push_back(p.passes[static_cast<size_t>(i)].id);
    CHECK(ids == std::vector<std::string>{"gbuffer", "bloom", "shadow", "composite"});
}

TEST_CASE("an output is read when a running pass binds it, it is the graph output, or it is viewed", "[plan][cull]") {
    // composite takes gbuffer.albedo for its normal too; the only other reader of
    // gbuffer.normal is bloom, culled (nothing reads bloom.color).
    const std::string json = R"({ "output": "composite.color", "passes": [
        { "id": "gbuffer", "module": "gbuffer" },
        { "id": "bloom", "module": "bloom", "inputs": { "color": "gbuffer.normal" } },
        { "id": "composite", "module": "composite", "inputs": { "albedo": "gbuffer.albedo",
          "normal": "gbuffer.albedo", "depth": "gbuffer.depth" } } ] })";
    auto read = [](const Plan& p, const std::string& id) { return pass(p, id).outputRead; };
    const Plan p = compileOk(json);
    REQUIRE(pass(p, "bloom").state == PassState::Culled);
    CHECK(read(p, "gbuffer") == std::vector<bool>{true, false, true});  // albedo, normal, depth
    CHECK(read(p, "bloom") == std::vector<bool>{false});
    CHECK(read(p, "composite") == std::vector<bool>{true});
    CHECK_THAT(p.table(), Contains("normal rgba16f 1x unread"));
    CHECK_THAT(p.table(), !Contains("albedo rgba8 1x unread"));

    // Viewing bloom's output runs bloom, which reads gbuffer.normal; viewing an internal
    // texture marks no output.
    const Plan viewed = compileOk(json, {"bloom.color", "bloom.ping"});
    CHECK(read(viewed, "gbuffer") == std::vector<bool>{true, true, true});
    CHECK(read(viewed, "bloom") == std::vector<bool>{true});
    const Plan normalViewed = compileOk(json, {"gbuffer.normal"});
    CHECK(read(normalViewed, "gbuffer") == std::vector<bool>{true, true, true});
    CHECK(pass(normalViewed, "bloom").state == PassState::Culled);
}

TEST_CASE("a pass feeding nothing is culled, and viewing its texture un-culls it", "[plan][cull]") {
    const Plan p = compileOk(kBasicPipeline);
    const PlannedPass& bloom = pass(p, "bloom");
    CHECK(bloom.state == PassState::Culled);
    CHECK(bloom.reason == "output not read by \"composite.color\" or any viewed texture");

    const Plan viewed = compileOk(kBasicPipeline, {"bloom.color"});
    CHECK(pass(viewed, "bloom").state == PassState::Run);
    CHECK(viewed.requested == std::vector<std::string>{"bloom.color"});
    CHECK(viewed.runOrder() == std::vector<int>{0, 1, 2, 3});

    // Internal textures are viewable too.
    CHECK(pass(compileOk(kBasicPipeline, {"bloom.ping"}), "bloom").state == PassState::Run);
}

TEST_CASE("culling follows chains: the producer of a culled pass is culled", "[plan][cull]") {
    const Plan p = compileOk(R"({ "output": "gbuffer.albedo", "passes": [
        { "id": "gbuffer", "module": "gbuffer" },
        { "id": "shadow", "module": "shadow" },
        { "id": "voxels", "module": "voxelize", "inputs": { "shadow_map": "shadow.depth" } },
        { "id": "gi", "module": "cone_trace", "inputs": { "voxels": "voxels.radiance",
          "normal": "gbuffer.normal", "depth": "gbuffer.depth" } } ] })");
    CHECK(p.runOrder() == std::vector<int>{0});
    CHECK(pass(p, "shadow").state == PassState::Culled);
    CHECK(pass(p, "voxels").state == PassState::Culled);
    CHECK(pass(p, "gi").state == PassState::Culled);

    const Plan viewed = compileOk(R"({ "output": "gbuffer.albedo", "passes": [
        { "id": "gbuffer", "module": "gbuffer" },
        { "id": "shadow", "module": "shadow" },
        { "id": "voxels", "module": "voxelize", "inputs": { "shadow_map": "shadow.depth" } } ] })",
                                  {"voxels.radiance"});
    CHECK(viewed.runOrder() == std::vector<int>{0, 1, 2});
}

TEST_CASE("requested textures that don't exist are warnings", "[plan][cull]") {
    const Plan p = compileOk(kBasicPipeline, {"blom.color", "bloom.colour", "bloom", "gbuffer.normal"});
    REQUIRE(p.warnings.size() == 3);
    CHECK_THAT(p.warnings[0].str(), Contains("warning: viewed texture \"blom.color\": no pass \"blom\" (did you mean \"bloom\"?)"));
    CHECK_THAT(p.warnings[1].str(), Contains("pass \"bloom\" has no texture \"colour\" (did you mean \"color\"?)"));
    CHECK_THAT(p.warnings[2].str(), Contains("viewed texture \"bloom\": expected"));
    CHECK(p.requested == std::vector<std::string>{"gbuffer.normal"});
    CHECK(pass(p, "bloom").state == PassState::Culled);
}

TEST_CASE("an optional input whose producer is disabled takes its fallback", "[plan]") {
    const std::string json = replaced(kBasicPipeline, R"("id": "shadow", "module": "shadow",)",
                                      R"("id": "shadow", "module": "shadow", "enabled": false,)");
    const Plan p = compileOk(json);
    CHECK(pass(p, "shadow").state == PassState::Disabled);
    CHECK(pass(p, "shadow").reason == "\"enabled\": false");
    const Binding* b = pass(p, "composite").binding("shadow_map");
    REQUIRE(b);
    CHECK_FALSE(b->bound());
    CHECK(b->fallback == Fallback::FarDepth);
    CHECK(b->lost == "shadow.depth");
    CHECK(p.runOrder() == std::vector<int>{0, 3});
    CHECK_THAT(p.table(), Contains("shadow_map←fallback:far_depth (shadow.depth disabled)"));
}

TEST_CASE("parameters: defaults overlaid with the file, typed", "[plan][params]") {
    const Plan p = compileOk(kBasicPipeline);
    const PlannedPass& c = pass(p, "composite");
    REQUIRE(c.params.values.size() == 4);
    CHECK(*c.params.get<float>("exposure") == 1.5f);
    CHECK(*c.params.get<std::string>("tonemap") == "reinhard");
    CHECK(*c.params.get<Color3>("tint") == Color3{1.0f, 0.9f, 0.8f});
    CHECK(*c.params.get<bool>("pcf") == true);  // default
    CHECK(c.params.get<int>("exposure") == nullptr);
    CHECK(*pass(p, "shadow").params.get<int>("size") == 2048);
    CHECK(*pass(p, "shadow").params.get<float>("bias") == 0.002f);

    // A float parameter accepts a JSON integer.
    const Plan q = compileOk(replaced(kBasicPipeline, R"("exposure": 1.5)", R"("exposure": 2)"));
    CHECK(*pass(q, "composite").params.get<float>("exposure") == 2.0f);
}

TEST_CASE("resolveSize", "[plan][size]") {
    ResolvedParams params;
    params.values.push_back({"size", 2048});
    params.values.push_back({"res", 64});
    TextureDecl t;
    t.size = SizeRule::relative();
    CHECK(resolveSize(t, 1280, 720, params) == Extent{1280, 720, 1});
    t.size = SizeRule::relative(0.5f);
    CHECK(resolveSize(t, 1281, 719, params) == Extent{641, 360, 1});  // rounded
    t.size = SizeRule::relative(0.001f);
    CHECK(resolveSize(t, 100, 100, params) == Extent{1, 1, 1});  // at least 1
    t.size = SizeRule::fixed(256, 128);
    CHECK(resolveSize(t, 1280, 720, params) == Extent{256, 128, 1});
    t.size = SizeRule::fromParam("size");
    CHECK(resolveSize(t, 1280, 720, params) == Extent{2048, 2048, 1});
    t.kind = TextureKind::Color3D;
    t.size = SizeRule::fromParam("res");
    CHECK(resolveSize(t, 1280, 720, params) == Extent{64, 64, 64});
    // A grid shaped like the scene's bounds: each axis halved `shift` times; a slab
    // atlas keeps its tiles along x; a 2D texture takes no shape.
    const GridShape flat{{0, 1, 2}};
    CHECK(resolveSize(t, 1280, 720, params, nullptr, flat) == Extent{64, 32, 16});
    t.size = SizeRule::fromParam("res", 1.0f, 3);
    CHECK(resolveSize(t, 1280, 720, params, nullptr, flat) == Extent{192, 32, 16});
    t.kind = TextureKind::Color2D;
    t.size = SizeRule::fromParam("size");
    CHECK(resolveSize(t, 1280, 720, params, nullptr, flat) == Extent{2048, 2048, 1});
    t.kind = TextureKind::Color3D;
    t.size = SizeRule::fixed(32, 16, 8);
    CHECK(resolveSize(t, 1280, 720, params) == Extent{32, 16, 8});
    CHECK(describeSize(t, params) == "32x16x8");
    // The output size ÷ an int parameter (cone_trace's strided trace).
    t.kind = TextureKind::Color2D;
    params.values.push_back({"stride", 4});
    t.size = SizeRule::relativeOverParam("stride");
    CHECK(resolveSize(t, 1280, 720, params) == Extent{320, 180, 1});
    CHECK(resolveSize(t, 1281, 722, params) == Extent{320, 181, 1});  // rounded
    CHECK(describeSize(t, params) == "1x / stride (4)");
    t.size = SizeRule::relativeOverParam("stride", 2.0f);
    CHECK(resolveSize(t, 1280, 720, params) == Extent{640, 360, 1});
    t.size = SizeRule::relativeOverParam("missing");  // the compiler reports it; sizes stay sane
    CHECK(resolveSize(t, 1280, 720, params) == Extent{1280, 720, 1});
    // Capped: at most `cap` texels across the longer side, the divisor raised to ⌈1280/cap⌉.
    params.values.push_back({"cap", 100});
    t.size = SizeRule::relativeOverParam("stride", 1.0f, "cap");
    CHECK(sizeDivisor(4, 100, 1280, 720) == 13);
    CHECK(resolveSize(t, 1280, 720, params) == Extent{98, 55, 1});
    CHECK(describeSize(t, params) == "1x / stride (4), at most 100 across (cap)");
    CHECK(resolveSize(t, 256, 256, params) == Extent{64, 64, 1});  // stride 4 already gives fewer
    CHECK(sizeDivisor(4, 0, 1280, 720) == 4);                       // cap 0: none
    CHECK(sizeDivisor(0, 0, 1280, 720) == 1);
    CHECK(sizeDivisor(1, 64, 128, 256) == 4);                       // the longer side, either axis
}

TEST_CASE("fromInput sizes follow the producer through the bindings", "[plan][size]") {
    // voxelize's radiance is a resolution³ cube; halve's output is half of whatever is
    // bound to its input, and a second halve halves that again.
    auto plan = compileText(R"({"output": "composite.color", "passes": [
        {"id": "gbuffer", "module": "gbuffer"},
        {"id": "shadow", "module": "shadow"},
        {"id": "voxelize", "module": "voxelize", "inputs": {"shadow_map": "shadow.depth"},
         "params": {"resolution": 128}},
        {"id": "h1", "module": "halve", "inputs": {"volume": "voxelize.radiance"}},
        {"id": "h2", "module": "halve", "inputs": {"volume": "h1.half"}},
        {"id": "composite", "module": "composite",
         "inputs": {"albedo": "gbuffer.albedo", "normal": "gbuffer.normal", "depth": "gbuffer.depth"}}]})",
                            "x.json", fakeOptions({"h2.half"}));
    INFO(plan.errorText());
    REQUIRE(plan.ok());
    CHECK(plan->extentOf(plan->find("voxelize"), "radiance", 640, 480) == Extent{128, 128, 128});
    CHECK(plan->extentOf(plan->find("h1"), "half", 640, 480) == Extent{64, 64, 64});
    CHECK(plan->extentOf(plan->find("h2"), "half", 640, 480) == Extent{32, 32, 32});
    CHECK(plan->extentOf(plan->find("gbuffer"), "albedo", 640, 480) == Extent{640, 480, 1});
    CHECK(describeSize(*plan->passes[size_t(plan->find("h1"))].output("half"), {}) == "0.50× as input volume");
    // Tiles side by side along x (voxel_mip's fixed-cone strip: 12 half-size cubes).
    CHECK(plan->extentOf(plan->find("h1"), "strip", 640, 480) == Extent{12 * 64, 64, 64});
    CHECK(describeSize(*plan->passes[size_t(plan->find("h1"))].output("strip"), {}) ==
          "0.50× as input volume ×12 tiles");
    // Unknown pass or texture: the 1×1×1 of "nothing".
    CHECK(plan->extentOf(99, "half", 640, 480) == Extent{});
    CHECK(plan->extentOf(plan->find("h1"), "nope", 640, 480) == Extent{});
}

TEST_CASE("a fromInput size that names no input is the module's bug, reported against the pass", "[plan][size]") {
    auto plan = compileText(R"({"output": "composite.color", "passes": [
        {"id": "gbuffer", "module": "gbuffer"},
        {"id": "shadow", "module": "shadow"},
        {"id": "voxelize", "module": "voxelize", "inputs": {"shadow_map": "shadow.depth"}},
        {"id": "copy", "module": "input_sized_wrong", "inputs": {"volume": "voxelize.radiance"}},
        {"id": "composite", "module": "composite",
         "inputs": {"albedo": "gbuffer.albedo", "normal": "gbuffer.normal", "depth": "gbuffer.depth"}}]})",
                            "x.json", fakeOptions());
    REQUIRE_FALSE(plan.ok());
    CHECK_THAT(plan.errorText(), Catch::Contains("output \"copy\" takes its size from unknown input \"volum\""));
}

TEST_CASE("the table lists every pass with its state", "[plan][print]") {
    const std::string json = replaced(kBasicPipeline, R"("id": "shadow", "module": "shadow",)",
                                      R"("id": "shadow", "module": "shadow", "enabled": false,)");
    const std::string t = compileOk(json).table();
    INFO(t);
    CHECK_THAT(t, Contains("#  id"));
    CHECK_THAT(t, Contains("0  gbuffer    gbuffer    run"));
    CHECK_THAT(t, Contains("1  shadow     shadow     disabled: \"enabled\": false"));
    CHECK_THAT(t, Contains("2  bloom      bloom      culled: output not read by \"composite.color\" or any viewed texture"));
    CHECK_THAT(t, Contains("3  composite  composite  run"));
    CHECK_THAT(t, Contains("albedo←gbuffer.albedo"));
    CHECK_THAT(t, Contains("gi←fallback:black"));
    CHECK_THAT(t, Contains("depth depth32f 1x"));
    CHECK_THAT(t, Contains("depth depth32f 2048² (size)"));
    CHECK_THAT(t, Contains("ping rgba16f 0.5x internal"));
    CHECK_THAT(t, Contains("output: composite.color"));
    // Fixed width: every continuation line of composite starts its inputs in the same column.
    const size_t header = t.find("inputs");
    const size_t lineStart = t.rfind('\n', t.find("normal←gbuffer.normal")) + 1;
    CHECK(t.substr(lineStart, t.find("normal←gbuffer.normal") - lineStart).size() == header);
}

TEST_CASE("dot output is well formed: balanced braces, an edge per binding", "[plan][print]") {
    const std::string json = replaced(kBasicPipeline, R"("id": "shadow", "module": "shadow",)",
                                      R"("id": "shadow", "module": "shadow", "enabled": false,)");
    const Plan p = compileOk(json);
    const std::string d = p.dot();
    INFO(d);
    CHECK(d.rfind("digraph pipeline {", 0) == 0);
    int depth = 0, minDepth = 0;
    bool inString = false;
    for (size_t i = 0; i < d.size(); ++i) {
        if (d[i] == '\\') { ++i; continue; }
        if (d[i] == '"') inString = !inString;
        if (inString) continue;
        if (d[i] == '{') ++depth;
        if (d[i] == '}') minDepth = std::min(minDepth, --depth);
    }
    CHECK(depth == 0);
    CHECK(minDepth == 0);
    CHECK_FALSE(inString);

    size_t edges = 0;
    for (size_t at = d.find("->"); at != std::string::npos; at = d.find("->", at + 2)) ++edges;
    size_t bindings = 0;
    for (const PlannedPass& pp : p.passes)
        for (const Binding& b : pp.bindings) bindings += (b.bound() || !b.lost.empty()) ? 1 : 0;
    CHECK(bindings == 5);  // bloom.color, composite's albedo/normal/depth, the lost shadow_map
    CHECK(edges == bindings + 1);  // + the graph output
    CHECK_THAT(d, Contains("p0 -> p3 [label=\"albedo\""));
    CHECK_THAT(d, Contains("p1 -> p3 [label=\"shadow_map (fallback: far_depth)\", style=dashed"));
    CHECK_THAT(d, Contains("p3 -> output [label=\"color\"]"));
    CHECK_THAT(d, Contains("p2 [label=\"bloom\\nculled\", style=\"rounded,filled\""));
    CHECK_THAT(d, Contains("p1 [label=\"shadow\\ndisabled\", style=\"rounded,dashed\""));
}

TEST_CASE("signatures: own params change it, unrelated passes don't", "[plan][signature]") {
    const Plan a = compileOk(kBasicPipeline);
    for (const PlannedPass& pp : a.passes) {
        CHECK_FALSE(pp.signature.empty());
        CHECK(pp.signatureHash != 0);
    }
    // Same file again: everything unchanged.
    const Plan same = compileOk(kBasicPipeline);
    PlanDiff d = diffPlans(a, same);
    CHECK(d.unchanged.size() == 4);
    CHECK(d.changed.empty());

    // Shadow's size changes: shadow changes, composite (which reads it) does not.
    const Plan b = compileOk(replaced(kBasicPipeline, R"("size": 2048)", R"("size": 4096)"));
    CHECK(pass(b, "shadow").signature != pass(a, "shadow").signature);
    CHECK(pass(b, "composite").signature == pass(a, "composite").signature);
    CHECK(pass(b, "composite").signatureHash == pass(a, "composite").signatureHash);
    d = diffPlans(a, b);
    CHECK(d.changed == std::vector<std::string>{"shadow"});
    CHECK(d.isUnchanged("composite"));
    CHECK(d.isUnchanged("gbuffer"));
    CHECK_FALSE(d.isUnchanged("shadow"));

    // Own params change: composite changes.
    const Plan c = compileOk(replaced(kBasicPipeline, R"("exposure": 1.5)", R"("exposure": 2.5)"));
    CHECK(pass(c, "composite").signature != pass(a, "composite").signature);
    CHECK(pass(c, "shadow").signature == pass(a, "shadow").signature);

    // Writing a default explicitly changes nothing (signatures use resolved values).
    const Plan e = compileOk(replaced(kBasicPipeline, R"("exposure": 1.5)", R"("exposure": 1.5, "pcf": true)"));
    CHECK(pass(e, "composite").signature == pass(a, "composite").signature);

    // Rebinding an input changes the consumer.
    const Plan f = compileOk(replaced(kBasicPipeline, R"("shadow_map": "shadow.depth")", R"("shadow_map": "gbuffer.depth")"));
    CHECK(pass(f, "composite").signature != pass(a, "composite").signature);
}

TEST_CASE("diffPlans reports added and removed passes", "[plan][signature]") {
    const Plan a = compileOk(kBasicPipeline);
    const Plan b = compileOk(R"({ "output": "gbuffer.albedo", "passes": [
        { "id": "gbuffer", "module": "gbuffer" },
        { "id": "shadow2", "module": "shadow", "params": { "size": 2048 } } ] })");
    const PlanDiff d = diffPlans(a, b);
    CHECK(d.unchanged == std::vector<std::string>{"gbuffer"});
    CHECK(d.added == std::vector<std::string>{"shadow2"});
    CHECK(d.removed == std::vector<std::string>{"shadow", "bloom", "composite"});
}

TEST_CASE("a module is resolved once per compile", "[plan]") {
    int calls = 0;
    CompileOptions o = fakeOptions();
    ModuleResolver inner = o.resolve;
    o.resolve = [&](const std::string& m) { ++calls; return inner(m); };
    Result<Plan> r = compileText(R"({ "output": "gbuffer.albedo", "passes": [
        { "id": "gbuffer", "module": "gbuffer" },
        { "id": "b1", "module": "bloom", "inputs": { "color": "gbuffer.albedo" } },
        { "id": "b2", "module": "bloom", "inputs": { "color": "b1.color" } } ] })",
                                 "p.json", o);
    REQUIRE(r.ok());
    CHECK(calls == 2);
}

TEST_CASE("a resolver that throws is an error, not a crash", "[plan]") {
    CompileOptions o = fakeOptions();
    o.resolve = [](const std::string&) -> Result<PassDeclaration> { throw std::runtime_error("boom"); };
    Result<Plan> r = compileText(R"({ "output": "g.albedo", "passes": [ { "id": "g", "module": "gbuffer" } ] })", "p.json", o);
    REQUIRE_FALSE(r.ok());
    CHECK_THAT(r.errorText(), Contains("p.json: passes[0].module: module \"gbuffer\": resolver threw: boom"));
}
