// graph/pipeline.hpp — the pipeline file as plain data, and its reader/writer.
//
// A pipeline file (pipelines/*.json, schema in pipelines/pipeline.schema.json):
//
//     {
//       "note": "prose goes in note fields; comments are not JSON",
//       "output": "composite.color",
//       "passes": [
//         { "id": "gbuffer", "module": "gbuffer" },
//         { "id": "shadow", "module": "shadow", "params": { "size": 2048 } },
//         { "id": "composite", "module": "composite", "enabled": true,
//           "inputs": { "albedo": "gbuffer.albedo", "shadow_map": "shadow.depth" },
//           "params": { "exposure": 1.0 } }
//       ]
//     }
//
// parsePipeline() checks only the *shape* of the file (JSON syntax, key names, value
// types) and keeps everything else as written; the meaning (do the modules, slots,
// outputs and parameters exist, do the kinds match) is compile()'s job
// (graph/compiler.hpp), because it needs the modules' declarations. A PipelineDesc
// can also be built or edited in code (the debug view's enable toggles and parameter
// widgets do), and written back with writePipeline().
//
// No nlohmann types appear here: parameter values are kept as ParamLiteral.
#pragma once

#include "graph/diagnostic.hpp"
#include "kiln/declare.hpp"

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace kiln::graph {

// A parameter value as written in the file, before it is checked against the
// declaration (which is where "2048.5 is not an int" is decided).
struct ParamLiteral {
    enum class Type : uint8_t { Null, Bool, Int, Float, String, Array, Object };
    Type type = Type::Null;
    bool b = false;
    int64_t i = 0;
    double f = 0.0;                   // also set for Int, so a float param can read it
    std::string s;                    // String
    std::vector<ParamLiteral> items;  // Array
    std::string text;                 // the value as compact JSON, for messages

    static ParamLiteral of(const ParamValue&);  // for the debug view writing params back
};
const char* toString(ParamLiteral::Type);  // "bool", "int", "float", "string", "array", ...

struct PassDesc {
    std::string id;
    std::string module;
    bool enabled = true;
    std::vector<std::pair<std::string, ParamLiteral>> params;  // in file order
    std::vector<std::pair<std::string, std::string>> inputs;   // slot → "<pass id>.<output>"
    std::string note;
};

struct PipelineDesc {
    std::string fileName;             // for messages; "pipelines/default.json"
    std::string schema;               // "$schema", kept so writing back keeps it
    std::string note;
    std::string output;               // "<pass id>.<output>"; "" when missing
    std::vector<PassDesc> passes;     // in execution order (= file order)

    // Index of the pass with this id, or -1 (the first one if ids repeat).
    int find(const std::string& id) const;
};

// Reads a pipeline. Errors: JSON syntax (file:line:col), duplicate keys, unknown keys
// (with the nearest known key), values of the wrong JSON type. All are collected.
Result<PipelineDesc> parsePipeline(const std::string& text, const std::string& fileName);

// Writes a pipeline back as pretty JSON (2-space indent, keys in the canonical
// order; "enabled" only when false, empty params/inputs left out).
std::string writePipeline(const PipelineDesc&);

// Byte offset (0-based) → 1-based line and column (column counts bytes).
void lineColumn(const std::string& text, size_t offset, int& line, int& column);

}  // namespace kiln::graph
