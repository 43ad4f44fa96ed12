// The pipeline files that ship in pipelines/ parse, and the schema agrees with the
// parser about which keys exist. (tests/integration/test_pipelines.cpp compiles them
// against the real modules.)
#include "graph/pipeline.hpp"

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

using namespace kiln::graph;
namespace fs = std::filesystem;

namespace {
std::string readFile(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

std::set<std::string> keysOf(const nlohmann::json& object) {
    std::set<std::string> keys;
    for (auto it = object.begin(); it != object.end(); ++it) keys.insert(it.key());
    return keys;
}
}  // namespace

TEST_CASE("every shipped pipeline file parses", "[files]") {
    const fs::path dir = KILN_PIPELINE_DIR;
    REQUIRE(fs::is_directory(dir));
    int count = 0;
    for (const auto& entry : fs::directory_iterator(dir)) {
        const fs::path p = entry.path();
        if (p.extension() != ".json" || p.filename() == "pipeline.schema.json") continue;
        ++count;
        Result<PipelineDesc> r = parsePipeline(readFile(p), "pipelines/" + p.filename().string());
        INFO(r.errorText());
        CHECK(r.ok());
    }
    CHECK(count >= 4);  // default, iso_mips, direct_only, voxels
}

TEST_CASE("the schema knows the same keys as the parser", "[files]") {
    const nlohmann::json schema = nlohmann::json::parse(readFile(fs::path(KILN_PIPELINE_DIR) / "pipeline.schema.json"));
    CHECK(schema.at("$schema") == "https://json-schema.org/draft/2020-12/schema");
    CHECK(keysOf(schema.at("properties")) == std::set<std::string>{"$schema", "extends", "note", "output", "passes"});
    CHECK(schema.at("additionalProperties") == false);
    const nlohmann::json& pass = schema.at("$defs").at("pass");
    CHECK(keysOf(pass.at("properties")) == std::set<std::string>{"id", "module", "enabled", "note", "inputs", "params", "remove", "before", "after"});
    CHECK(pass.at("additionalProperties") == false);
    CHECK(pass.at("properties").at("id").contains("$ref"));
    CHECK(schema.at("$defs").at("name").at("pattern") == "^[a-z0-9_]+$");
}
