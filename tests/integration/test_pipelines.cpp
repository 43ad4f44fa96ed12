// Every pipeline file that ships in pipelines/ compiles against the real pass modules:
// its modules load, its parameters are declared and in range, its bindings type-check,
// and its output exists. No GL context is needed: declarations are plain data.
#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "graph/compiler.hpp"
#include "run/module_registry.hpp"

namespace fs = std::filesystem;
using namespace kiln;

TEST_CASE("every shipped pipeline compiles against the real modules, without warnings", "[integration][files]") {
    run::ModuleRegistry modules({fs::path(KILN_BUILD_MODULE_DIR)});
    graph::CompileOptions options;
    options.resolve = [&](const std::string& m) { return modules.declaration(m); };
    options.availableModules = modules.loader().available();
    REQUIRE(options.availableModules.size() >= 8);  // the shipped passes were built

    int compiled = 0;
    for (const char* dir : {"pipelines", "bench/pipelines"})
    for (const auto& entry : fs::directory_iterator(fs::path(KILN_SOURCE_DIR) / dir)) {
        const fs::path p = entry.path();
        if (p.extension() != ".json" || p.filename() == "pipeline.schema.json") continue;
        std::ifstream in(p);
        std::stringstream text;
        text << in.rdbuf();
        auto plan = graph::compileText(text.str(), std::string(dir) + "/" + p.filename().string(), options);
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
