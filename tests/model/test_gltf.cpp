// The glTF loader (host/model): every file of Debian's assimp-testmodels made to break
// loaders gives one error naming the file and where, every valid one loads; files the
// tests write themselves check what each part of the format becomes.
#include <catch2/catch.hpp>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>

#include "model/model.hpp"
#include "support/base64.hpp"

using kiln::model::Model;
namespace fs = std::filesystem;

namespace {

const std::string kModels = ASSIMP_MODELS;

std::string loadError(const std::string& path) {
    Model m;
    std::string error;
    if (kiln::model::loadGltf(path, m, error)) return {};
    return error;
}

using kiln::test::base64;

// A glTF written by the test: one buffer (a data URI) that views and accessors append to.
struct Writer {
    nlohmann::json j = {{"asset", {{"version", "2.0"}}}};
    std::vector<uint8_t> bin;

    template <class T>
    int view(const std::vector<T>& data) {
        while (bin.size() % 4) bin.push_back(0);
        const size_t offset = bin.size();
        const auto* p = reinterpret_cast<const uint8_t*>(data.data());
        bin.insert(bin.end(), p, p + data.size() * sizeof(T));
        j["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", offset}, {"byteLength", data.size() * sizeof(T)}});
        return int(j["bufferViews"].size()) - 1;
    }
    template <class T>
    int accessor(const std::vector<T>& data, int componentType, const char* type, size_t count) {
        j["accessors"].push_back({{"bufferView", view(data)}, {"componentType", componentType}, {"count", count}, {"type", type}});
        return int(j["accessors"].size()) - 1;
    }
    int positions(const std::vector<float>& xyz) { return accessor(xyz, 5126, "VEC3", xyz.size() / 3); }
    std::string text() {
        nlohmann::json out = j;
        out["buffers"] = {{{"byteLength", bin.size()}, {"uri", "data:application/octet-stream;base64," + base64(bin)}}};
        return out.dump();
    }
    bool load(Model& m, std::string& error) {
        const std::string t = text();
        return kiln::model::loadGltfFromMemory("test.gltf", reinterpret_cast<const uint8_t*>(t.data()), t.size(), "", m,
                                               error);
    }
};

// A unit quad (two triangles) in z = 0 as one mesh placed by one node.
Writer quad(std::vector<uint32_t> indices = {0, 1, 2, 0, 2, 3}, int indexType = 5125) {
    Writer w;
    const int pos = w.positions({0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0});
    nlohmann::json prim = {{"attributes", {{"POSITION", pos}}}};
    if (indexType == 5121) {
        std::vector<uint8_t> i8(indices.begin(), indices.end());
        prim["indices"] = w.accessor(i8, 5121, "SCALAR", i8.size());
    } else if (indexType == 5123) {
        std::vector<uint16_t> i16(indices.begin(), indices.end());
        prim["indices"] = w.accessor(i16, 5123, "SCALAR", i16.size());
    } else if (indexType == 5125) {
        prim["indices"] = w.accessor(indices, 5125, "SCALAR", indices.size());
    }
    w.j["meshes"] = {{{"primitives", {prim}}}};
    w.j["nodes"] = {{{"mesh", 0}}};
    w.j["scenes"] = {{{"nodes", {0}}}};
    w.j["scene"] = 0;
    return w;
}

}  // namespace

TEST_CASE("the malformed glTF files of assimp-testmodels each give one named error") {
    if (!fs::exists(kModels)) FAIL("assimp-testmodels is not installed (scripts/setup.sh installs it)");
    // file → what its one-line error must say (the file's name is checked for every one).
    const std::vector<std::pair<std::string, std::string>> cases = {
        {"BoxBadNormals-glTF-Binary/BoxBadNormals.glb", "meshes[0].primitives[0].attributes.NORMAL: element"},
        {"BoxWithInfinites-glTF-Binary/BoxWithInfinites.glb", "is not finite"},
        {"IncorrectVertexArrays/Cube.gltf", "meshes[1].primitives[0].attributes.POSITION: 35 vertices (no indices) for TRIANGLES"},
        {"IndexOutOfRange/IndexOutOfRange.gltf", "meshes[0].primitives[0].indices: index"},
        {"IndexOutOfRange/AllIndicesOutOfRange.gltf", "meshes[0].primitives[0].indices: index"},
        {"MissingBin/BoxTextured.gltf", "buffers[0].uri: cannot read"},
        {"RecursiveNodes/RecursiveNodes.gltf", "nodes["},
        {"SchemaFailures/sceneWrongType.gltf", "scene: expected an index"},
        {"TestNoRootNode/NoScene.gltf", "scene: scene 0 but the file has no scenes"},
        {"TestNoRootNode/SceneWithoutNodes.gltf", "scenes[0].nodes: nothing to draw"},
        {"wrongTypes/badArray.gltf", "expected"},
        {"wrongTypes/badExtension.gltf", "extensions"},
        {"wrongTypes/badNumber.gltf", "expected"},
        {"wrongTypes/badObject.gltf", "expected"},
        {"wrongTypes/badString.gltf", "expected a string"},
        {"wrongTypes/badUint.gltf", "baseColorTexture.index: expected an index"},
    };
    for (const auto& [file, expected] : cases) {
        INFO(file);
        const std::string error = loadError(kModels + "/" + file);
        INFO(error);
        CHECK(error.find(file.substr(file.find('/') + 1)) != std::string::npos);
        CHECK(error.find(expected) != std::string::npos);
        CHECK(error.find('\n') == std::string::npos);
    }
}

TEST_CASE("texcoord_crash loads, its out-of-range texture coordinates kept as given") {
    Model m;
    std::string error;
    REQUIRE(kiln::model::loadGltf(kModels + "/issue_3269/texcoord_crash.gltf", m, error));
    CHECK(!m.meshes.empty());
}

TEST_CASE("every valid glTF 2.0 file of assimp-testmodels loads") {
    const std::vector<std::string> valid = {
        "2CylinderEngine-glTF-Binary/2CylinderEngine.glb", "BoxTexcoords-glTF/boxTexcoords.gltf",
        "BoxTextured-glTF/BoxTextured.gltf", "BoxTextured-glTF-Binary/BoxTextured.glb",
        "BoxTextured-glTF-Embedded/BoxTextured.gltf", "BoxTextured-glTF-pbrSpecularGlossiness/BoxTextured.gltf",
        "ClearCoat-glTF/ClearCoatTest.gltf",
        "cameras/Cameras.gltf", "glTF-Sample-Models/AnimatedMorphCube-glTF/AnimatedMorphCube.gltf",
        "simple_skin/simple_skin.gltf", "textureTransform/TextureTransformTest.gltf"};
    for (const std::string& file : valid) {
        INFO(file);
        Model m;
        std::string error;
        CHECK(kiln::model::loadGltf(kModels + "/" + file, m, error));
        INFO(error);
        CHECK(error.empty());
        CHECK(m.triangles() > 0);
    }
    // A required extension Kiln does not read is refused, as glTF asks of a loader.
    CHECK(loadError(kModels + "/BoxTextured-glTF-techniqueWebGL/BoxTextured.gltf")
              .find("extensionsRequired[0]: \"KHR_technique_webgl\" is required") != std::string::npos);
    // The primitive modes: triangles, strips and fans become triangles; points and lines
    // load and draw nothing (a warning says so).
    for (int mode = 0; mode <= 15; ++mode) {
        char name[128];
        std::snprintf(name, sizeof name, "%s/glTF-Asset-Generator/Mesh_PrimitiveMode/Mesh_PrimitiveMode_%02d.gltf",
                      kModels.c_str(), mode);
        Model m;
        std::string error;
        INFO(name << ": " << error);
        const bool ok = kiln::model::loadGltf(name, m, error);
        CHECK((ok || error.find("nothing to draw") != std::string::npos));
    }
}

TEST_CASE("2CylinderEngine: its triangles and materials as the file states them") {
    Model m;
    std::string error;
    REQUIRE(kiln::model::loadGltf(kModels + "/2CylinderEngine-glTF-Binary/2CylinderEngine.glb", m, error));
    // Counted from the file's JSON by another reader (Python): 75 730 triangles in its 29
    // meshes, 121 496 drawn by its 82 nodes (several place the same mesh).
    uint64_t unique = 0;
    for (const auto& mesh : m.meshes) unique += mesh.indices.size() / 3;
    CHECK(unique == 75730);
    CHECK(m.triangles() == 121496);
    CHECK(m.materials.size() == 34);
    CHECK(m.files.size() == 1);
    CHECK(glm::all(glm::lessThan(m.boundsMin, m.boundsMax)));
}

TEST_CASE("the textured box reads the same from .gltf, .glb and embedded data") {
    Model a, b, c;
    std::string error;
    REQUIRE(kiln::model::loadGltf(kModels + "/BoxTextured-glTF/BoxTextured.gltf", a, error));
    REQUIRE(kiln::model::loadGltf(kModels + "/BoxTextured-glTF-Binary/BoxTextured.glb", b, error));
    REQUIRE(kiln::model::loadGltf(kModels + "/BoxTextured-glTF-Embedded/BoxTextured.gltf", c, error));
    for (const Model* m : {&a, &b, &c}) {
        REQUIRE(m->meshes.size() == 1);
        REQUIRE(m->images.size() == 1);
        REQUIRE(m->materials.size() == 1);
        CHECK(m->materials[0].baseColorTexture == 0);
        CHECK(m->triangles() == 12);
        CHECK(m->images[0].rgba == a.images[0].rgba);
        CHECK(m->meshes[0].indices == a.meshes[0].indices);
        for (size_t v = 0; v < a.meshes[0].vertices.size(); ++v) {
            CHECK(m->meshes[0].vertices[v].uv == a.meshes[0].vertices[v].uv);
            CHECK(m->meshes[0].vertices[v].position == a.meshes[0].vertices[v].position);
        }
    }
    // The external files were read and are listed for the live reload to watch.
    CHECK(a.files.size() == 3);  // the .gltf, its .bin and its .png
}

TEST_CASE("every index width and none give the same triangles") {
    for (int type : {5121, 5123, 5125, 0}) {
        Writer w = quad({0, 1, 2, 0, 2, 3}, type);
        if (type == 0) {  // non-indexed: six vertices
            w = Writer();
            const int pos = w.positions({0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 0, 0, 1, 1, 0, 0, 1, 0});
            w.j["meshes"] = {{{"primitives", {{{"attributes", {{"POSITION", pos}}}}}}}};
            w.j["nodes"] = {{{"mesh", 0}}};
            w.j["scenes"] = {{{"nodes", {0}}}};
        }
        Model m;
        std::string error;
        INFO(type << " " << error);
        REQUIRE(w.load(m, error));
        REQUIRE(m.meshes.size() == 1);
        CHECK(m.meshes[0].indices.size() == 6);
        // No NORMAL: flat normals, here +z for the counter-clockwise quad.
        for (const auto& v : m.meshes[0].vertices) CHECK(v.normal.z == Approx(1.0f));
    }
}

TEST_CASE("an index beyond the vertices is named at its JSON path") {
    Writer w = quad({0, 1, 2, 0, 2, 40});
    Model m;
    std::string error;
    REQUIRE_FALSE(w.load(m, error));
    CHECK(error == "test.gltf: meshes[0].primitives[0].indices: index 40 (element 5) beyond the 4 vertices of "
                   "attributes.POSITION");
}

TEST_CASE("strips and fans become triangle lists with the strip's winding kept") {
    Writer w = quad({0, 1, 3, 2}, 5125);
    w.j["meshes"][0]["primitives"][0]["mode"] = 5;
    Model m;
    std::string error;
    REQUIRE(w.load(m, error));
    REQUIRE(m.meshes[0].indices.size() == 6);
    for (const auto& v : m.meshes[0].vertices) CHECK(v.normal.z == Approx(1.0f));  // both faces towards +z
    Writer f = quad({0, 1, 2, 3}, 5125);
    f.j["meshes"][0]["primitives"][0]["mode"] = 6;
    REQUIRE(f.load(m, error));
    CHECK(m.meshes[0].indices.size() == 6);
}

TEST_CASE("node transforms compose parent to child, TRS and matrix alike") {
    Writer w = quad();
    // Parent: translate (10, 0, 0); child: scale 2 then rotate 90° about z.
    const float s = std::sqrt(0.5f);
    w.j["nodes"] = {{{"translation", {10, 0, 0}}, {"children", {1}}},
                    {{"mesh", 0}, {"rotation", {0, 0, s, s}}, {"scale", {2, 2, 2}}}};
    Model m;
    std::string error;
    REQUIRE(w.load(m, error));
    REQUIRE(m.instances.size() == 1);
    const glm::vec4 p = m.instances[0].transform * glm::vec4(1, 0, 0, 1);  // (1,0,0) → scale (2,0,0) → rotate (0,2,0) → (10,2,0)
    CHECK(p.x == Approx(10.0f));
    CHECK(p.y == Approx(2.0f));
    CHECK(m.boundsMin.x == Approx(8.0f));
    CHECK(m.boundsMax.y == Approx(2.0f));
    // The same as a matrix.
    w.j["nodes"][0].erase("translation");
    w.j["nodes"][0]["matrix"] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 10, 0, 0, 1};
    REQUIRE(w.load(m, error));
    const glm::vec4 q = m.instances[0].transform * glm::vec4(1, 0, 0, 1);
    CHECK(q.x == Approx(10.0f));
    CHECK(q.y == Approx(2.0f));
}

TEST_CASE("a node hierarchy with a cycle, or a node with two parents, is refused") {
    Writer w = quad();
    w.j["nodes"] = {{{"mesh", 0}, {"children", {1}}}, {{"children", {2}}}, {{"children", {1}}}};
    Model m;
    std::string error;
    REQUIRE_FALSE(w.load(m, error));
    CHECK(error.find("nodes[2].children[0]: node 1 already has a parent, nodes[0]") != std::string::npos);
    w.j["nodes"] = {{{"mesh", 0}}, {{"children", {2}}}, {{"children", {1}}}};
    REQUIRE_FALSE(w.load(m, error));
    CHECK(error.find("its own ancestor") != std::string::npos);
}

TEST_CASE("materials: factors, textures, emissive strength, alpha mask, double-sided") {
    Writer w = quad();
    w.j["materials"] = {{{"pbrMetallicRoughness", {{"baseColorFactor", {0.5, 0.25, 1.0, 1.0}}, {"metallicFactor", 0.0},
                                                   {"roughnessFactor", 0.3}}},
                         {"emissiveFactor", {1.0, 0.5, 0.0}},
                         {"extensions", {{"KHR_materials_emissive_strength", {{"emissiveStrength", 7.0}}}}},
                         {"alphaMode", "MASK"},
                         {"alphaCutoff", 0.25},
                         {"doubleSided", true}}};
    w.j["meshes"][0]["primitives"][0]["material"] = 0;
    Model m;
    std::string error;
    REQUIRE(w.load(m, error));
    const auto& mat = m.materials.at(0);
    CHECK(mat.baseColorFactor == glm::vec4(0.5f, 0.25f, 1.0f, 1.0f));
    CHECK(mat.metallicFactor == 0.0f);
    CHECK(mat.roughnessFactor == Approx(0.3f));
    CHECK(mat.emissiveFactor == glm::vec3(1.0f, 0.5f, 0.0f));
    CHECK(mat.emissiveStrength == 7.0f);
    CHECK(mat.alphaMode == kiln::model::AlphaMode::Mask);
    CHECK(mat.alphaCutoff == 0.25f);
    CHECK(mat.doubleSided);
    CHECK(m.meshes[0].material == 0);
    // A texture index beyond the textures is an error at its path.
    w.j["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"] = {{"index", 3}};
    REQUIRE_FALSE(w.load(m, error));
    CHECK(error == "test.gltf: materials[0].pbrMetallicRoughness.baseColorTexture.index: texture 3 beyond the file's 0 "
                   "textures");
}

TEST_CASE("KHR_lights_punctual: each light placed and aimed by its node") {
    Writer w = quad();
    w.j["extensionsUsed"] = {"KHR_lights_punctual"};
    w.j["extensions"] = {{"KHR_lights_punctual",
                          {{"lights",
                            {{{"type", "spot"}, {"color", {1, 0.5, 0.25}}, {"intensity", 40}, {"spot", {{"innerConeAngle", 0.2}, {"outerConeAngle", 0.5}}}},
                             {{"type", "directional"}, {"intensity", 3}}}}}}};
    const float s = std::sqrt(0.5f);
    // The spot at (0, 5, 0) turned to look down (−z rotated −90° about x is −y).
    w.j["nodes"].push_back({{"translation", {0, 5, 0}}, {"rotation", {-s, 0, 0, s}},
                            {"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}});
    w.j["nodes"].push_back({{"extensions", {{"KHR_lights_punctual", {{"light", 1}}}}}});
    w.j["scenes"][0]["nodes"] = {0, 1, 2};
    Model m;
    std::string error;
    INFO(error);
    REQUIRE(w.load(m, error));
    REQUIRE(m.lights.size() == 2);
    CHECK(m.lights[0].type == kiln::model::Light::Type::Spot);
    CHECK(m.lights[0].position.y == Approx(5.0f));
    CHECK(m.lights[0].direction.y == Approx(-1.0f));
    CHECK(m.lights[0].innerCone == Approx(0.2f));
    CHECK(m.lights[0].outerCone == Approx(0.5f));
    CHECK(m.lights[0].intensity == 40.0f);
    CHECK(m.lights[1].type == kiln::model::Light::Type::Directional);
    CHECK(m.lights[1].direction.z == Approx(-1.0f));
    // A node naming a light the file lacks.
    w.j["nodes"][2]["extensions"]["KHR_lights_punctual"]["light"] = 9;
    REQUIRE_FALSE(w.load(m, error));
    CHECK(error.find("nodes[2].extensions.KHR_lights_punctual.light: expected a light index below 2") != std::string::npos);
}

TEST_CASE("a perspective camera keeps its node's frame without scale") {
    Writer w = quad();
    w.j["cameras"] = {{{"type", "perspective"}, {"perspective", {{"yfov", 0.7}, {"znear", 0.1}, {"aspectRatio", 1.5}}}}};
    w.j["nodes"].push_back({{"camera", 0}, {"translation", {1, 2, 3}}, {"scale", {4, 4, 4}}});
    w.j["scenes"][0]["nodes"] = {0, 1};
    Model m;
    std::string error;
    REQUIRE(w.load(m, error));
    REQUIRE(m.cameras.size() == 1);
    CHECK(m.cameras[0].yfov == Approx(0.7f));
    CHECK(m.cameras[0].aspect == Approx(1.5f));
    CHECK(glm::vec3(m.cameras[0].transform[3]) == glm::vec3(1, 2, 3));
    CHECK(glm::length(glm::vec3(m.cameras[0].transform[0])) == Approx(1.0f));
}

TEST_CASE("a sparse accessor's substitutions are applied") {
    Writer w = quad();
    // Move vertex 2 to (5, 5, 0) through a sparse substitution on the positions.
    const int idxView = w.view(std::vector<uint16_t>{2, 0});
    const int valView = w.view(std::vector<float>{5, 5, 0});
    w.j["accessors"][0]["sparse"] = {{"count", 1},
                                     {"indices", {{"bufferView", idxView}, {"componentType", 5123}}},
                                     {"values", {{"bufferView", valView}}}};
    Model m;
    std::string error;
    INFO(error);
    REQUIRE(w.load(m, error));
    bool found = false;
    for (const auto& v : m.meshes[0].vertices) found |= v.position == glm::vec3(5, 5, 0);
    CHECK(found);
}

TEST_CASE("limits: triangles, file size and texture side are named errors") {
    Writer w = quad();
    const std::string t = w.text();
    Model m;
    std::string error;
    kiln::model::Limits small;
    small.triangles = 1;
    REQUIRE_FALSE(kiln::model::loadGltfFromMemory("test.gltf", reinterpret_cast<const uint8_t*>(t.data()), t.size(), "",
                                                  m, error, small));
    CHECK(error.find("the scene's triangles pass the limit of 1") != std::string::npos);
    small = {};
    small.fileBytes = 100;
    REQUIRE_FALSE(kiln::model::loadGltfFromMemory("test.gltf", reinterpret_cast<const uint8_t*>(t.data()), t.size(), "",
                                                  m, error, small));
    CHECK(error.find("over the limit of 100 bytes") != std::string::npos);
    small = {};
    small.textureSide = 64;
    REQUIRE_FALSE(kiln::model::loadGltf(kModels + "/BoxTextured-glTF/BoxTextured.gltf", m, error, small));
    CHECK(error.find("beyond the 64 texels a side") != std::string::npos);
}

TEST_CASE("a required extension Kiln does not read is refused by name") {
    Writer w = quad();
    w.j["extensionsUsed"] = {"KHR_draco_mesh_compression"};
    w.j["extensionsRequired"] = {"KHR_draco_mesh_compression"};
    Model m;
    std::string error;
    REQUIRE_FALSE(w.load(m, error));
    CHECK(error.find("extensionsRequired[0]: \"KHR_draco_mesh_compression\" is required") != std::string::npos);
}
