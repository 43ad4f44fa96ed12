// graph/pipeline_json.hpp — what reading, writing and patching pipeline files share
// (pipeline.cpp, pipeline_patch.cpp): the JSON type that keeps the file's key order,
// the nesting bound, JSON paths for messages, and a literal as JSON.
#pragma once

#include <nlohmann/json.hpp>

#include <string>

#include "graph/pipeline.hpp"
#include "kiln/json_path.hpp"

namespace kiln::graph {

using Json = nlohmann::ordered_json;  // keeps the file's key order (params, inputs)

// Deeper than any pipeline needs (passes[i].params.x[j] is 4): bounds the stack of
// everything that walks the parsed value, and the size of every message about it.
inline constexpr int kMaxNesting = 32;

// JSON paths for messages: "passes[2].params.size", params["my key"] (common/).
using json_text::indexPath;
using json_text::keyPath;
// An object literal is kept as its text; one that is not JSON comes back discarded.
Json toJson(const ParamLiteral& l);

}  // namespace kiln::graph
