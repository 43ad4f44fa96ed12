// model/gltf_schema.hpp — the JSON types of the glTF properties Kiln reads, checked
// before tinygltf parses them (it skips a mistyped optional property silently).
#pragma once

#include <string>

#include <nlohmann/json.hpp>

namespace kiln::model {

struct SchemaError {
    std::string path;     // JSON path, e.g. "materials[0].pbrMetallicRoughness.baseColorTexture.index"
    std::string message;  // what is wrong
};

// True when every property Kiln reads has its schema type and asset.version is 2.x.
bool checkGltfSchema(const nlohmann::json& root, SchemaError& error);

}  // namespace kiln::model
