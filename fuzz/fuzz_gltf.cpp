// Fuzz target: the glTF loader. Any input, .gltf text or .glb bytes, must give a model
// or one bounded, named error; an accepted model must be one the renderer can upload
// as it stands: every index within its mesh, every reference within its table, every
// number finite.
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "model/model.hpp"

namespace {
void require(bool ok, const char* what, const std::string& detail = {}) {
    if (ok) return;
    std::fprintf(stderr, "fuzz_gltf: invariant broken: %s\n%.2000s\n", what, detail.c_str());
    std::abort();
}
bool finite(glm::vec3 v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    using namespace kiln::model;
    Limits limits;
    limits.fileBytes = size_t(4) << 20;  // small bounds keep each input fast
    limits.triangles = 200'000;
    limits.vertices = 400'000;
    limits.textureSide = 1024;
    Model m;
    std::string error;
    if (!loadGltfFromMemory("fuzz.gltf", data, size, "", m, error, limits)) {
        require(!error.empty(), "a failed load with no error");
        require(error.size() <= 700, "an error message longer than 700 bytes", error);
        require(error.find('\n') == std::string::npos, "an error message of several lines", error);
        require(error.rfind("fuzz.gltf: ", 0) == 0, "an error that does not name the file", error);
        return 0;
    }
    require(m.triangles() <= limits.triangles, "more triangles than the limit");
    for (const Mesh& mesh : m.meshes) {
        require(mesh.indices.size() % 3 == 0, "a mesh of partial triangles");
        require(mesh.material < int(m.materials.size()), "a mesh's material out of range");
        for (uint32_t i : mesh.indices) require(i < mesh.vertices.size(), "an index beyond its mesh");
        for (const Vertex& v : mesh.vertices)
            require(finite(v.position) && finite(v.normal) && std::isfinite(v.uv.x) && std::isfinite(v.uv.y),
                    "a vertex is not finite");
    }
    for (const Instance& inst : m.instances) {
        require(inst.mesh >= 0 && size_t(inst.mesh) < m.meshes.size(), "an instance's mesh out of range");
        for (int c = 0; c < 4; ++c) require(finite(glm::vec3(inst.transform[c])), "an instance's transform is not finite");
    }
    for (const Texture& t : m.textures) require(t.image < int(m.images.size()), "a texture's image out of range");
    for (const Image& im : m.images)
        require(im.rgba.size() == size_t(im.width) * size_t(im.height) * 4, "an image's pixels do not fill it");
    for (const Material& mat : m.materials)
        for (int t : {mat.baseColorTexture, mat.emissiveTexture, mat.normalTexture, mat.metallicRoughnessTexture})
            require(t < int(m.textures.size()), "a material's texture out of range");
    return 0;
}
