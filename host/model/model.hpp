// model/model.hpp — a scene model read from a file (glTF 2.0), as plain CPU data: the
// meshes flattened to indexed triangle lists with every attribute Kiln draws, the
// materials, the images decoded to RGBA8, the instances with their world transforms,
// the cameras, the punctual lights and the bounds. No OpenGL: the loader is tested and
// fuzzed alone, and the host uploads what it returns (host/scene).
//
// A load either returns a whole model or one error naming the file, the JSON path and
// what is wrong (`meshes[3].primitives[0].indices: index 40 beyond the 12 vertices of
// attributes.POSITION`): nothing half-read reaches the renderer.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>

namespace kiln::model {

struct Vertex {
    glm::vec3 position{0.0f};
    glm::vec3 normal{0.0f, 1.0f, 0.0f};
    glm::vec2 uv{0.0f};       // TEXCOORD_0 (0 where the primitive has none)
    glm::vec4 tangent{1.0f, 0.0f, 0.0f, 1.0f};  // xyz, w = bitangent sign (glTF's TANGENT)
};

// One glTF primitive, as triangles (strips and fans unrolled).
struct Mesh {
    std::string name;           // "mesh name/primitive index" for messages
    std::vector<Vertex> vertices;
    std::vector<uint32_t> indices;
    int material = -1;          // into Model::materials; -1: glTF's default material
    glm::vec3 boundsMin{0.0f}, boundsMax{0.0f};
};

struct Image {
    std::string name;           // its uri, or "images[i]"
    int width = 0, height = 0;
    std::vector<uint8_t> rgba;  // width × height × 4, rows top to bottom as in the file
};

enum class Wrap : uint8_t { Repeat, ClampToEdge, MirroredRepeat };

struct Texture {
    int image = -1;             // into Model::images
    Wrap wrapS = Wrap::Repeat, wrapT = Wrap::Repeat;
    bool nearest = false;       // magFilter NEAREST
};

enum class AlphaMode : uint8_t { Opaque, Mask, Blend };

// glTF's metallic-roughness material. Texture indices are into Model::textures (-1:
// none); each texture reads TEXCOORD_0 (a material naming another set is loaded with a
// warning and reads set 0).
struct Material {
    std::string name;
    glm::vec4 baseColorFactor{1.0f};   // linear
    int baseColorTexture = -1;         // sRGB
    float metallicFactor = 1.0f, roughnessFactor = 1.0f;
    int metallicRoughnessTexture = -1; // linear: G roughness, B metallic
    glm::vec3 emissiveFactor{0.0f};    // linear, × emissiveStrength
    float emissiveStrength = 1.0f;     // KHR_materials_emissive_strength
    int emissiveTexture = -1;          // sRGB
    int normalTexture = -1;            // linear, tangent space
    float normalScale = 1.0f;
    AlphaMode alphaMode = AlphaMode::Opaque;
    float alphaCutoff = 0.5f;
    bool doubleSided = false;
};

struct Instance {
    int mesh = -1;              // into Model::meshes
    int node = -1;              // the glTF node that places it
    glm::mat4 transform{1.0f};  // model → world (the node's and its ancestors')
};

struct Camera {
    std::string name;
    glm::mat4 transform{1.0f};  // camera → world; it looks along its −z, +y up
    float yfov = 0.8f;          // radians
    float aspect = 0.0f;        // 0: the output's
    float znear = 0.05f, zfar = 0.0f;  // zfar 0: infinite
};

struct Light {
    enum class Type : uint8_t { Directional, Point, Spot };
    std::string name;
    Type type = Type::Point;
    glm::vec3 color{1.0f};
    float intensity = 1.0f;     // candela (point, spot) or lux (directional)
    float range = 0.0f;         // 0: infinite
    float innerCone = 0.0f, outerCone = 0.785398163f;  // spot, radians from the axis
    glm::vec3 position{0.0f};   // world
    glm::vec3 direction{0.0f, 0.0f, -1.0f};  // world, unit: where it shines
};

struct Model {
    std::vector<Mesh> meshes;
    std::vector<Image> images;
    std::vector<Texture> textures;
    std::vector<Material> materials;
    std::vector<Instance> instances;
    std::vector<Camera> cameras;
    std::vector<Light> lights;
    glm::vec3 boundsMin{0.0f}, boundsMax{0.0f};  // of every instance, world space
    std::vector<std::string> files;     // every file read: the glTF, its buffers, its images
    std::vector<std::string> warnings;  // what was read but is not drawn (lines, skins, ...)
    uint64_t triangles() const;
};

// Bounds on what one file may ask for; each is a named error with the limit in it.
struct Limits {
    size_t fileBytes = size_t(512) << 20;     // the glTF or .glb, and each buffer or image file
    uint64_t triangles = 4'000'000;           // over every instance
    uint64_t vertices = 8'000'000;            // over every mesh
    int textureSide = 8192;                   // an image's width or height
    size_t images = 256;
    size_t instances = 100'000;
    int nodeDepth = 64;                       // the node hierarchy's nesting
};

// Loads a .gltf (external buffers and images, data URIs) or a .glb. On failure returns
// false and sets `error` to one line "FILE: PATH: MESSAGE" (PATH is the JSON path, empty
// where the file as a whole is wrong); `out` is left untouched.
bool loadGltf(const std::string& path, Model& out, std::string& error, const Limits& limits = {});
// The same from bytes in memory (the fuzzer): `name` stands for the file in messages,
// `baseDir` resolves relative URIs ("" refuses them).
bool loadGltfFromMemory(const std::string& name, const uint8_t* bytes, size_t size, const std::string& baseDir,
                        Model& out, std::string& error, const Limits& limits = {});

}  // namespace kiln::model
