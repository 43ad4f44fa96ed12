// Every pipeline file that ships in pipelines/ compiles against the real pass modules:
// its modules load, its parameters are declared and in range, its bindings type-check,
// and its output exists (declarations are plain data: no GL context). And every program
// they build, under every choice of every enum and bool parameter, stays within what
// OpenGL 4.5 guarantees (a GL context).
#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "app/app.hpp"
#include "graph/compiler.hpp"
#include "run/module_registry.hpp"
#include "support/headless.hpp"

namespace fs = std::filesystem;
using namespace kiln;

namespace {
std::vector<fs::path> shippedPipelines() {
    std::vector<fs::path> files;
    for (const char* dir : {"pipelines", "bench/pipelines"})
        for (const auto& entry : fs::directory_iterator(fs::path(KILN_SOURCE_DIR) / dir))
            if (entry.path().extension() == ".json" && entry.path().filename() != "pipeline.schema.json")
                files.push_back(entry.path());
    std::sort(files.begin(), files.end());
    return files;
}
}  // namespace

TEST_CASE("every shipped pipeline compiles against the real modules, without warnings", "[integration][files]") {
    run::ModuleRegistry modules({fs::path(KILN_BUILD_MODULE_DIR)});
    graph::CompileOptions options;
    options.resolve = [&](const std::string& m) { return modules.declaration(m); };
    options.availableModules = modules.loader().available();
    REQUIRE(options.availableModules.size() >= 8);  // the shipped passes were built

    int compiled = 0;
    for (const fs::path& p : shippedPipelines()) {
        std::ifstream in(p);
        std::stringstream text;
        text << in.rdbuf();
        auto plan = graph::compileText(text.str(), fs::relative(p, KILN_SOURCE_DIR).string(), options);
        INFO(p.filename().string() << ":\n" << plan.errorText());
        REQUIRE(plan.ok());
        CHECK(plan->warnings.empty());
        CHECK(plan->output.valid());
        CHECK_FALSE(plan->runOrder().empty());
        ++compiled;
    }
    // default, iso_mips, direct_only, voxels, and the two benchmark pipelines at least.
    CHECK(compiled >= 6);
}

// llvmpipe links programs that NVIDIA's driver refuses (voxelize once bound ten
// accumulator images, units 0-9, where NVIDIA has 8): the host names such a use as a
// portability warning (tests/core/test_shader.cpp), and no shipped program may have one.
// Each pipeline runs a frame at 16², then each enum parameter at each of its other
// choices and each bool flipped, one at a time, so variant programs are built too.
TEST_CASE("every program of every shipped pipeline and parameter choice stays within OpenGL 4.5's guarantees",
          "[integration][files][gl]") {
    REQUIRE(test::ensureHeadlessContext());
    int pipelinesChecked = 0, variants = 0;
    for (const fs::path& file : shippedPipelines()) {
        INFO(file.filename().string());
        app::App app;
        std::string error;
        REQUIRE(app.init(test::pausedHeadlessOptions(16), error));
        run::Runtime& runtime = app.runtime();
        INFO(error);
        REQUIRE(runtime.loadPipeline(file, error));
        app.frame();
        for (auto& e : runtime.activeErrors()) FAIL(e);
        for (auto& w : runtime.portabilityWarnings()) FAIL(w);
        const graph::Plan plan = *runtime.plan();
        for (const graph::PlannedPass& pass : plan.passes) {
            if (!pass.runs()) continue;
            for (const ParamDecl& param : pass.decl.params) {
                std::vector<ParamValue> others;
                const ParamValue* found = pass.params.find(param.name);
                REQUIRE(found);
                const ParamValue current = *found;
                if (param.type == ParamType::Bool) others.push_back(!std::get<bool>(current));
                if (param.type == ParamType::Enum)
                    for (const std::string& choice : param.choices)
                        if (choice != std::get<std::string>(current)) others.push_back(choice);
                for (const ParamValue& value : others) {
                    INFO(pass.id << "." << param.name << " = " << graph::formatParamValue(value));
                    // Refused by name where the pipeline's bindings need the current choice
                    // (voxel_mip's mode feeds cone_trace's inputs): a state no user reaches.
                    error.clear();
                    if (!runtime.setParam(pass.id, param.name, value, error)) {
                        CHECK_FALSE(error.empty());
                        continue;
                    }
                    app.frame();
                    for (auto& w : runtime.portabilityWarnings()) FAIL(w);
                    ++variants;
                }
                if (!others.empty()) REQUIRE(runtime.setParam(pass.id, param.name, current, error));
            }
        }
        ++pipelinesChecked;
    }
    CHECK(pipelinesChecked >= 14);  // 9 in pipelines/, 6 in bench/pipelines/ less the schema
    // The shipped passes' enum and bool parameters, over each pipeline that runs them.
    CHECK(variants >= 100);
}
