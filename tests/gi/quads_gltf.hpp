// glTF scenes of flat quads for the GI tests, written as a user's file would be: a
// mesh per list of quads, materials as glTF's metallic-roughness ones.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <nlohmann/json.hpp>

#include "gi/rig.hpp"
#include "support/base64.hpp"

namespace kiln::test {

struct Quad {
    std::array<glm::vec3, 4> corners;  // in order around it
    int material;
};

// A mesh per list of quads, a primitive per quad (two triangles 0-1-2, 0-2-3; no normals:
// the loader makes them flat), a node per mesh (untransformed: set "translation",
// "rotation" or "scale" on it) and the given materials.
inline nlohmann::json quadsGltf(const std::vector<std::vector<Quad>>& meshes, const nlohmann::json& materials) {
    std::vector<uint8_t> bin;
    auto append = [&](const void* p, size_t n) {
        bin.insert(bin.end(), static_cast<const uint8_t*>(p), static_cast<const uint8_t*>(p) + n);
    };
    nlohmann::json accessors = nlohmann::json::array(), views = nlohmann::json::array(),
                   meshList = nlohmann::json::array(), nodes = nlohmann::json::array(), roots = nlohmann::json::array();
    for (const std::vector<Quad>& quads : meshes) {
        nlohmann::json primitives = nlohmann::json::array();
        for (const Quad& q : quads) {
            const size_t at = bin.size();
            append(q.corners.data(), sizeof q.corners);
            const uint16_t idx[6] = {0, 1, 2, 0, 2, 3};
            append(idx, sizeof idx);
            bin.resize((bin.size() + 3) / 4 * 4);
            glm::vec3 lo = q.corners[0], hi = q.corners[0];
            for (const glm::vec3& c : q.corners) lo = glm::min(lo, c), hi = glm::max(hi, c);
            const int view = int(views.size());
            views.push_back({{"buffer", 0}, {"byteOffset", at}, {"byteLength", 48}});
            views.push_back({{"buffer", 0}, {"byteOffset", at + 48}, {"byteLength", 12}});
            const int accessor = int(accessors.size());
            accessors.push_back({{"bufferView", view}, {"componentType", 5126}, {"count", 4}, {"type", "VEC3"},
                                 {"min", {lo.x, lo.y, lo.z}}, {"max", {hi.x, hi.y, hi.z}}});
            accessors.push_back({{"bufferView", view + 1}, {"componentType", 5123}, {"count", 6}, {"type", "SCALAR"}});
            primitives.push_back(
                {{"attributes", {{"POSITION", accessor}}}, {"indices", accessor + 1}, {"material", q.material}});
        }
        roots.push_back(nodes.size());
        nodes.push_back({{"mesh", meshList.size()}});
        meshList.push_back({{"primitives", primitives}});
    }
    return {{"asset", {{"version", "2.0"}}},
            {"scene", 0},
            {"scenes", {{{"nodes", roots}}}},
            {"nodes", nodes},
            {"meshes", meshList},
            {"accessors", accessors},
            {"bufferViews", views},
            {"buffers", {{{"byteLength", bin.size()}, {"uri", "data:application/octet-stream;base64," + base64(bin)}}}},
            {"materials", materials}};
}

inline nlohmann::json diffuse(glm::vec3 albedo, glm::vec3 emission = glm::vec3(0.0f), bool doubleSided = true) {
    return {{"pbrMetallicRoughness", {{"baseColorFactor", {albedo.x, albedo.y, albedo.z, 1.0}}, {"metallicFactor", 0.0}}},
            {"emissiveFactor", {emission.x, emission.y, emission.z}},
            {"doubleSided", doubleSided}};
}

// The six faces of the cube [-h, h]³.
inline std::vector<Quad> cubeFaces(float h, int material) {
    std::vector<Quad> q;
    for (int axis = 0; axis < 3; ++axis)
        for (float side : {-h, h}) {
            const int u = (axis + 1) % 3, v = (axis + 2) % 3;
            Quad f{{}, material};
            const float uv[4][2] = {{-h, -h}, {h, -h}, {h, h}, {-h, h}};
            for (int k = 0; k < 4; ++k) {
                f.corners[size_t(k)][axis] = side;
                f.corners[size_t(k)][u] = uv[k][0];
                f.corners[size_t(k)][v] = uv[k][1];
            }
            q.push_back(f);
        }
    return q;
}

// A scene file placing `gltf` (written beside it) with the given "box" settings.
inline std::string sceneWithModel(const std::string& name, const nlohmann::json& gltf, const nlohmann::json& box) {
    writeScene(name + ".gltf", gltf.dump());
    return writeScene(name + ".json", nlohmann::json({{"box", box},
                                                      {"tumblers", nlohmann::json::array()},
                                                      {"marbles", nlohmann::json::array()},
                                                      {"fireballs", nlohmann::json::array()},
                                                      {"models", {{{"file", name + ".gltf"}}}}})
                                          .dump());
}

}  // namespace kiln::test
