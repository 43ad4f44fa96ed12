// The types of the glTF 2.0 properties Kiln reads, checked on the JSON before tinygltf
// sees it: tinygltf skips an optional property of the wrong type without a word
// ("scene": "hello" loads as though it were absent), and a file that says something
// Kiln cannot read must be refused at its JSON path, not read as something else.
#include "model/gltf_schema.hpp"

#include <map>

namespace kiln::model {

namespace {

using Json = nlohmann::json;

enum class Kind { Index, Uint, Number, Bool, String, Object, NumberArray, IndexArray, ObjectArray, StringArray, Any };

const char* describe(Kind k) {
    switch (k) {
        case Kind::Index: return "an index (an integer >= 0)";
        case Kind::Uint: return "an integer >= 0";
        case Kind::Number: return "a number";
        case Kind::Bool: return "true or false";
        case Kind::String: return "a string";
        case Kind::Object: return "an object";
        case Kind::NumberArray: return "an array of numbers";
        case Kind::IndexArray: return "an array of indices (integers >= 0)";
        case Kind::ObjectArray: return "an array of objects";
        case Kind::StringArray: return "an array of strings";
        case Kind::Any: return "anything";
    }
    return "?";
}

std::string quoted(const Json& v) {
    std::string s = v.dump();
    if (s.size() > 40) s = s.substr(0, 37) + "...";
    return s;
}

bool isUint(const Json& v) { return v.is_number_unsigned() || (v.is_number_integer() && v.get<int64_t>() >= 0); }

bool matches(const Json& v, Kind k) {
    switch (k) {
        case Kind::Index:
        case Kind::Uint: return isUint(v);
        case Kind::Number: return v.is_number();
        case Kind::Bool: return v.is_boolean();
        case Kind::String: return v.is_string();
        case Kind::Object: return v.is_object();
        case Kind::NumberArray:
            if (!v.is_array()) return false;
            for (const Json& e : v)
                if (!e.is_number()) return false;
            return true;
        case Kind::IndexArray:
            if (!v.is_array()) return false;
            for (const Json& e : v)
                if (!isUint(e)) return false;
            return true;
        case Kind::ObjectArray:
            if (!v.is_array()) return false;
            for (const Json& e : v)
                if (!e.is_object()) return false;
            return true;
        case Kind::StringArray:
            if (!v.is_array()) return false;
            for (const Json& e : v)
                if (!e.is_string()) return false;
            return true;
        case Kind::Any: return true;
    }
    return false;
}

// Properties of one kind of object: name → its kind, and for objects within, their own
// table. Keys not listed are allowed (glTF allows extensions' and newer versions' keys).
struct Shape {
    std::map<std::string, Kind> fields;
    std::map<std::string, const Shape*> children;  // Object or ObjectArray fields
};

const Shape& textureInfo() {
    static const Shape s{{{"index", Kind::Index}, {"texCoord", Kind::Uint}, {"scale", Kind::Number},
                          {"strength", Kind::Number}},
                         {}};
    return s;
}

const Shape& rootShape() {
    static const Shape asset{{{"version", Kind::String}, {"minVersion", Kind::String}, {"generator", Kind::String}}, {}};
    static const Shape accessor{{{"bufferView", Kind::Index}, {"byteOffset", Kind::Uint}, {"componentType", Kind::Uint},
                                 {"normalized", Kind::Bool}, {"count", Kind::Uint}, {"type", Kind::String},
                                 {"max", Kind::NumberArray}, {"min", Kind::NumberArray}, {"sparse", Kind::Object},
                                 {"name", Kind::String}},
                                {}};
    static const Shape bufferView{{{"buffer", Kind::Index}, {"byteOffset", Kind::Uint}, {"byteLength", Kind::Uint},
                                   {"byteStride", Kind::Uint}, {"target", Kind::Uint}, {"name", Kind::String}},
                                  {}};
    static const Shape buffer{{{"uri", Kind::String}, {"byteLength", Kind::Uint}, {"name", Kind::String}}, {}};
    static const Shape attributes{{}, {}};
    static const Shape primitive{{{"attributes", Kind::Object}, {"indices", Kind::Index}, {"material", Kind::Index},
                                  {"mode", Kind::Uint}, {"targets", Kind::ObjectArray}},
                                 {}};
    static const Shape mesh{{{"primitives", Kind::ObjectArray}, {"weights", Kind::NumberArray}, {"name", Kind::String}},
                            {{"primitives", &primitive}}};
    static const Shape node{{{"camera", Kind::Index}, {"children", Kind::IndexArray}, {"skin", Kind::Index},
                             {"matrix", Kind::NumberArray}, {"mesh", Kind::Index}, {"rotation", Kind::NumberArray},
                             {"scale", Kind::NumberArray}, {"translation", Kind::NumberArray},
                             {"weights", Kind::NumberArray}, {"name", Kind::String}},
                            {}};
    static const Shape pbr{{{"baseColorFactor", Kind::NumberArray}, {"baseColorTexture", Kind::Object},
                            {"metallicFactor", Kind::Number}, {"roughnessFactor", Kind::Number},
                            {"metallicRoughnessTexture", Kind::Object}},
                           {{"baseColorTexture", &textureInfo()}, {"metallicRoughnessTexture", &textureInfo()}}};
    static const Shape material{{{"name", Kind::String}, {"pbrMetallicRoughness", Kind::Object},
                                 {"normalTexture", Kind::Object}, {"occlusionTexture", Kind::Object},
                                 {"emissiveTexture", Kind::Object}, {"emissiveFactor", Kind::NumberArray},
                                 {"alphaMode", Kind::String}, {"alphaCutoff", Kind::Number},
                                 {"doubleSided", Kind::Bool}},
                                {{"pbrMetallicRoughness", &pbr},
                                 {"normalTexture", &textureInfo()},
                                 {"occlusionTexture", &textureInfo()},
                                 {"emissiveTexture", &textureInfo()}}};
    static const Shape texture{{{"sampler", Kind::Index}, {"source", Kind::Index}, {"name", Kind::String}}, {}};
    static const Shape image{{{"uri", Kind::String}, {"mimeType", Kind::String}, {"bufferView", Kind::Index},
                              {"name", Kind::String}},
                             {}};
    static const Shape sampler{{{"magFilter", Kind::Uint}, {"minFilter", Kind::Uint}, {"wrapS", Kind::Uint},
                                {"wrapT", Kind::Uint}, {"name", Kind::String}},
                               {}};
    static const Shape scene{{{"nodes", Kind::IndexArray}, {"name", Kind::String}}, {}};
    static const Shape perspective{{{"aspectRatio", Kind::Number}, {"yfov", Kind::Number}, {"zfar", Kind::Number},
                                    {"znear", Kind::Number}},
                                   {}};
    static const Shape camera{{{"type", Kind::String}, {"perspective", Kind::Object}, {"orthographic", Kind::Object},
                               {"name", Kind::String}},
                              {{"perspective", &perspective}}};
    static const Shape root{{{"asset", Kind::Object}, {"scene", Kind::Index}, {"scenes", Kind::ObjectArray},
                             {"nodes", Kind::ObjectArray}, {"meshes", Kind::ObjectArray},
                             {"accessors", Kind::ObjectArray}, {"bufferViews", Kind::ObjectArray},
                             {"buffers", Kind::ObjectArray}, {"materials", Kind::ObjectArray},
                             {"textures", Kind::ObjectArray}, {"images", Kind::ObjectArray},
                             {"samplers", Kind::ObjectArray}, {"cameras", Kind::ObjectArray},
                             {"skins", Kind::ObjectArray}, {"animations", Kind::ObjectArray},
                             {"extensionsUsed", Kind::StringArray}, {"extensionsRequired", Kind::StringArray}},
                            {{"asset", &asset},
                             {"accessors", &accessor},
                             {"bufferViews", &bufferView},
                             {"buffers", &buffer},
                             {"meshes", &mesh},
                             {"nodes", &node},
                             {"materials", &material},
                             {"textures", &texture},
                             {"images", &image},
                             {"samplers", &sampler},
                             {"scenes", &scene},
                             {"cameras", &camera}}};
    (void)attributes;
    return root;
}

bool checkObject(const Json& object, const Shape& shape, const std::string& path, SchemaError& error);

bool checkValue(const Json& value, Kind kind, const Shape* child, const std::string& path, SchemaError& error) {
    if (!matches(value, kind)) {
        error = {path, std::string("expected ") + describe(kind) + ", got " + quoted(value)};
        return false;
    }
    if (!child) return true;
    if (value.is_object()) return checkObject(value, *child, path, error);
    for (size_t i = 0; i < value.size(); ++i)
        if (!checkObject(value[i], *child, path + "[" + std::to_string(i) + "]", error)) return false;
    return true;
}

bool checkObject(const Json& object, const Shape& shape, const std::string& path, SchemaError& error) {
    const std::string prefix = path.empty() ? "" : path + ".";
    for (auto it = object.begin(); it != object.end(); ++it) {
        const std::string where = prefix + it.key();
        if (it.key() == "extensions" || it.key() == "extras") {
            if (it.key() == "extensions" && !it->is_object()) {
                error = {where, "expected an object (extension name → its object), got " + quoted(*it)};
                return false;
            }
            if (it.key() == "extensions")
                for (auto e = it->begin(); e != it->end(); ++e)
                    if (!e->is_object()) {
                        error = {where + "." + e.key(), "expected an object, got " + quoted(*e)};
                        return false;
                    }
            continue;
        }
        auto field = shape.fields.find(it.key());
        if (field == shape.fields.end()) continue;
        auto child = shape.children.find(it.key());
        if (!checkValue(*it, field->second, child == shape.children.end() ? nullptr : child->second, where, error))
            return false;
    }
    return true;
}

}  // namespace

bool checkGltfSchema(const nlohmann::json& root, SchemaError& error) {
    if (!root.is_object()) {
        error = {"", "the top level is not a JSON object"};
        return false;
    }
    if (!root.contains("asset")) {
        error = {"asset", "missing (every glTF file says its version there)"};
        return false;
    }
    if (!checkObject(root, rootShape(), "", error)) return false;
    // Within a primitive, attributes map names to accessor indices.
    if (root.contains("meshes"))
        for (size_t m = 0; m < root["meshes"].size(); ++m) {
            const Json& mesh = root["meshes"][m];
            if (!mesh.contains("primitives")) {
                error = {"meshes[" + std::to_string(m) + "].primitives", "missing (a mesh is its primitives)"};
                return false;
            }
            const Json& prims = mesh["primitives"];
            for (size_t p = 0; p < prims.size(); ++p) {
                const std::string at = "meshes[" + std::to_string(m) + "].primitives[" + std::to_string(p) + "]";
                if (!prims[p].contains("attributes")) {
                    error = {at + ".attributes", "missing"};
                    return false;
                }
                for (auto a = prims[p]["attributes"].begin(); a != prims[p]["attributes"].end(); ++a)
                    if (!isUint(*a)) {
                        error = {at + ".attributes." + a.key(), "expected an accessor index, got " + quoted(*a)};
                        return false;
                    }
            }
        }
    const Json& version = root["asset"].value("version", Json());
    if (!version.is_string() || version.get<std::string>().rfind("2.", 0) != 0) {
        error = {"asset.version", "Kiln reads glTF 2.x, this file says " + quoted(version)};
        return false;
    }
    return true;
}

}  // namespace kiln::model
