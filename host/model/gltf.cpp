// glTF 2.0 → model::Model. tinygltf (Debian's libtinygltf) parses the JSON, the GLB
// container, data URIs and external files; everything it hands over is checked here
// before it is used — every index against what it indexes, every accessor against its
// buffer view and buffer, every value finite — so a file made to break loaders gives one
// error at its JSON path instead of a read out of bounds.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <functional>
#include <sstream>

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>
#include <meshoptimizer.h>
#include <glm/gtc/type_ptr.hpp>
#include <stb_image.h>
#include <sys/stat.h>
#include <tiny_gltf.h>

#include "kiln/json_text.hpp"
#include "model/gltf_schema.hpp"
#include "model/model.hpp"

namespace kiln::model {

uint64_t Model::triangles() const {
    uint64_t n = 0;
    for (const Instance& i : instances) n += meshes[size_t(i.mesh)].indices.size() / 3;
    return n;
}

namespace {

// An error at a JSON path, thrown inside the loader and turned into one line at its top.
struct LoadError {
    std::string path, message;
};
[[noreturn]] void fail(std::string path, std::string message) { throw LoadError{std::move(path), std::move(message)}; }

std::string idx(const char* array, size_t i) { return std::string(array) + "[" + std::to_string(i) + "]"; }

std::string bytesText(size_t n) {
    char buf[32];
    if (n >= (size_t(1) << 20)) std::snprintf(buf, sizeof buf, "%.1f MiB", double(n) / double(1 << 20));
    else std::snprintf(buf, sizeof buf, "%zu bytes", n);
    return buf;
}

// What the file system callbacks and the image loader saw, for messages and for the
// list of files a live reload watches.
struct LoadState {
    const Limits* limits = nullptr;
    std::vector<std::string> files;
    std::string fsError;  // the last file that could not be read, and why
    size_t imageBytes = 0;
};

bool fileExists(const std::string& path, void*) {
    struct stat st{};
    return ::stat(path.c_str(), &st) == 0 && S_ISREG(st.st_mode);
}
// No shell-style expansion (tinygltf's default runs wordexp on every URI).
std::string expandPath(const std::string& path, void*) { return path; }

bool readWholeFile(std::vector<unsigned char>* out, std::string* err, const std::string& path, void* user) {
    auto* state = static_cast<LoadState*>(user);
    struct stat st{};
    if (::stat(path.c_str(), &st) != 0 || !S_ISREG(st.st_mode)) {
        state->fsError = path + ": no such file";
        if (err) *err += state->fsError + "\n";
        return false;
    }
    if (size_t(st.st_size) > state->limits->fileBytes) {
        state->fsError = path + ": " + bytesText(size_t(st.st_size)) + ", over the limit of " +
                         bytesText(state->limits->fileBytes);
        if (err) *err += state->fsError + "\n";
        return false;
    }
    std::ifstream in(path, std::ios::binary);
    out->resize(size_t(st.st_size));
    if (!in.read(reinterpret_cast<char*>(out->data()), std::streamsize(out->size()))) {
        state->fsError = path + ": cannot read";
        if (err) *err += state->fsError + "\n";
        return false;
    }
    state->files.push_back(path);
    return true;
}

bool writeWholeFile(std::string*, const std::string&, const std::vector<unsigned char>&, void*) { return false; }

// Decodes every image to RGBA8 with stb_image, its size checked before it is decoded.
bool loadImage(tinygltf::Image* image, const int index, std::string* err, std::string*, int, int,
               const unsigned char* bytes, int size, void* user) {
    auto* state = static_cast<LoadState*>(user);
    const std::string where = idx("images", size_t(index));
    int w = 0, h = 0, channels = 0;
    if (!stbi_info_from_memory(bytes, size, &w, &h, &channels)) {
        if (err) *err += where + ": not an image stb_image reads (" + (stbi_failure_reason() ? stbi_failure_reason() : "?") + ")";
        return false;
    }
    const int side = state->limits->textureSide;
    if (w < 1 || h < 1 || w > side || h > side) {
        if (err) *err += where + ": " + std::to_string(w) + "x" + std::to_string(h) + ", beyond the " + std::to_string(side) +
                         " texels a side Kiln accepts";
        return false;
    }
    const size_t decoded = size_t(w) * size_t(h) * 4;
    if (state->imageBytes + decoded > (size_t(2) << 30)) {
        if (err) *err += where + ": the images would take over 2 GiB decoded";
        return false;
    }
    stbi_uc* pixels = stbi_load_from_memory(bytes, size, &w, &h, &channels, 4);
    if (!pixels) {
        if (err) *err += where + ": cannot decode (" + (stbi_failure_reason() ? stbi_failure_reason() : "?") + ")";
        return false;
    }
    state->imageBytes += decoded;
    image->width = w;
    image->height = h;
    image->component = 4;
    image->bits = 8;
    image->pixel_type = TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE;
    image->image.assign(pixels, pixels + decoded);
    stbi_image_free(pixels);
    return true;
}

bool finite(glm::vec3 v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

int componentCount(int type) {
    switch (type) {
        case TINYGLTF_TYPE_SCALAR: return 1;
        case TINYGLTF_TYPE_VEC2: return 2;
        case TINYGLTF_TYPE_VEC3: return 3;
        case TINYGLTF_TYPE_VEC4: return 4;
        case TINYGLTF_TYPE_MAT2: return 4;
        case TINYGLTF_TYPE_MAT3: return 9;
        case TINYGLTF_TYPE_MAT4: return 16;
        default: return 0;
    }
}

int componentBytes(int componentType) {
    switch (componentType) {
        case TINYGLTF_COMPONENT_TYPE_BYTE:
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return 1;
        case TINYGLTF_COMPONENT_TYPE_SHORT:
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: return 2;
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
        case TINYGLTF_COMPONENT_TYPE_FLOAT: return 4;
        default: return 0;
    }
}

const char* componentName(int componentType) {
    switch (componentType) {
        case TINYGLTF_COMPONENT_TYPE_BYTE: return "BYTE";
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return "UNSIGNED_BYTE";
        case TINYGLTF_COMPONENT_TYPE_SHORT: return "SHORT";
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: return "UNSIGNED_SHORT";
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: return "UNSIGNED_INT";
        case TINYGLTF_COMPONENT_TYPE_FLOAT: return "FLOAT";
        default: return "an unknown component type";
    }
}

class Builder {
public:
    Builder(const tinygltf::Model& g, const Limits& limits, Model& out) : g_(g), limits_(limits), out_(out) {}

    void build() {
        checkExtensions();
        for (size_t i = 0; i < g_.images.size(); ++i) readImage(i);
        for (size_t i = 0; i < g_.textures.size(); ++i) readTexture(i);
        for (size_t i = 0; i < g_.materials.size(); ++i) readMaterial(i);
        meshPrimitives_.resize(g_.meshes.size());
        for (size_t i = 0; i < g_.meshes.size(); ++i) readMesh(i);
        for (size_t i = 0; i < g_.lights.size(); ++i) checkLight(i);
        readNodes();
        if (out_.instances.empty() && out_.lights.empty())
            fail(g_.scenes.empty() ? "" : sceneName_ + ".nodes", "nothing to draw: no node of the scene places a mesh");
        computeBounds();
    }

private:
    void warn(std::string text) {
        if (std::find(out_.warnings.begin(), out_.warnings.end(), text) == out_.warnings.end())
            out_.warnings.push_back(std::move(text));
    }

    void checkExtensions() {
        static const char* supported[] = {"KHR_lights_punctual", "KHR_materials_emissive_strength",
                                          "KHR_mesh_quantization"};
        for (size_t i = 0; i < g_.extensionsRequired.size(); ++i) {
            const std::string& e = g_.extensionsRequired[i];
            if (std::find(std::begin(supported), std::end(supported), e) == std::end(supported))
                fail(idx("extensionsRequired", i), "\"" + e + "\" is required and Kiln does not read it (it reads " +
                                                       "KHR_lights_punctual, KHR_materials_emissive_strength, " +
                                                       "KHR_mesh_quantization)");
        }
        for (const std::string& e : g_.extensionsUsed)
            if (std::find(std::begin(supported), std::end(supported), e) == std::end(supported))
                warn("extension " + e + " is used by the file and ignored by Kiln");
    }

    void readImage(size_t i) {
        const tinygltf::Image& im = g_.images[i];
        if (out_.images.size() >= limits_.images)
            fail(idx("images", i), "more than " + std::to_string(limits_.images) + " images");
        Image image;
        image.name = im.uri.empty() || im.uri.rfind("data:", 0) == 0 ? (im.name.empty() ? idx("images", i) : im.name)
                                                                      : im.uri;
        image.width = im.width;
        image.height = im.height;
        if (im.width < 1 || im.height < 1 || im.image.size() != size_t(im.width) * size_t(im.height) * 4)
            fail(idx("images", i), "no image data was read (a missing uri or bufferView)");
        image.rgba = im.image;
        out_.images.push_back(std::move(image));
    }

    int textureIndex(int index, const std::string& path) {
        if (index < 0) return -1;
        if (size_t(index) >= g_.textures.size())
            fail(path, "texture " + std::to_string(index) + " beyond the file's " + std::to_string(g_.textures.size()) +
                           " textures");
        return index;
    }

    void readTexture(size_t i) {
        const tinygltf::Texture& t = g_.textures[i];
        Texture tex;
        const std::string at = idx("textures", i);
        if (t.source >= 0) {
            if (size_t(t.source) >= g_.images.size())
                fail(at + ".source", "image " + std::to_string(t.source) + " beyond the file's " +
                                         std::to_string(g_.images.size()) + " images");
            tex.image = t.source;
        } else {
            warn(at + " has no source image (an extension's?): drawn without it");
        }
        if (t.sampler >= 0) {
            if (size_t(t.sampler) >= g_.samplers.size())
                fail(at + ".sampler", "sampler " + std::to_string(t.sampler) + " beyond the file's " +
                                          std::to_string(g_.samplers.size()) + " samplers");
            const tinygltf::Sampler& s = g_.samplers[size_t(t.sampler)];
            auto wrap = [&](int mode, const char* key) {
                switch (mode) {
                    case TINYGLTF_TEXTURE_WRAP_REPEAT: return Wrap::Repeat;
                    case TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE: return Wrap::ClampToEdge;
                    case TINYGLTF_TEXTURE_WRAP_MIRRORED_REPEAT: return Wrap::MirroredRepeat;
                    default:
                        fail(idx("samplers", size_t(t.sampler)) + "." + key,
                             std::to_string(mode) + " is not a wrap mode (10497, 33071 or 33648)");
                }
            };
            tex.wrapS = wrap(s.wrapS, "wrapS");
            tex.wrapT = wrap(s.wrapT, "wrapT");
            tex.nearest = s.magFilter == TINYGLTF_TEXTURE_FILTER_NEAREST;
        }
        out_.textures.push_back(tex);
    }

    static float number(const tinygltf::Value& v, double def) {
        return v.IsNumber() || v.IsInt() ? float(v.GetNumberAsDouble()) : float(def);
    }

    void readMaterial(size_t i) {
        const tinygltf::Material& m = g_.materials[i];
        const std::string at = idx("materials", i);
        Material mat;
        mat.name = m.name.empty() ? at : m.name;
        const auto& pbr = m.pbrMetallicRoughness;
        if (pbr.baseColorFactor.size() != 4)
            fail(at + ".pbrMetallicRoughness.baseColorFactor", "expected 4 numbers, got " +
                                                                   std::to_string(pbr.baseColorFactor.size()));
        mat.baseColorFactor = glm::vec4(float(pbr.baseColorFactor[0]), float(pbr.baseColorFactor[1]),
                                        float(pbr.baseColorFactor[2]), float(pbr.baseColorFactor[3]));
        for (int c = 0; c < 4; ++c)
            if (!(mat.baseColorFactor[c] >= 0.0f && mat.baseColorFactor[c] <= 1.0f))
                fail(at + ".pbrMetallicRoughness.baseColorFactor[" + std::to_string(c) + "]",
                     "must lie in [0, 1], is " + std::to_string(pbr.baseColorFactor[size_t(c)]));
        mat.baseColorTexture = textureIndex(pbr.baseColorTexture.index, at + ".pbrMetallicRoughness.baseColorTexture.index");
        mat.metallicFactor = float(pbr.metallicFactor);
        mat.roughnessFactor = float(pbr.roughnessFactor);
        if (!(mat.metallicFactor >= 0.0f && mat.metallicFactor <= 1.0f))
            fail(at + ".pbrMetallicRoughness.metallicFactor", "must lie in [0, 1]");
        if (!(mat.roughnessFactor >= 0.0f && mat.roughnessFactor <= 1.0f))
            fail(at + ".pbrMetallicRoughness.roughnessFactor", "must lie in [0, 1]");
        mat.metallicRoughnessTexture =
            textureIndex(pbr.metallicRoughnessTexture.index, at + ".pbrMetallicRoughness.metallicRoughnessTexture.index");
        if (m.emissiveFactor.size() != 3)
            fail(at + ".emissiveFactor", "expected 3 numbers, got " + std::to_string(m.emissiveFactor.size()));
        mat.emissiveFactor = glm::vec3(float(m.emissiveFactor[0]), float(m.emissiveFactor[1]), float(m.emissiveFactor[2]));
        if (!finite(mat.emissiveFactor) || glm::any(glm::lessThan(mat.emissiveFactor, glm::vec3(0.0f))))
            fail(at + ".emissiveFactor", "must be finite and >= 0");
        if (auto e = m.extensions.find("KHR_materials_emissive_strength"); e != m.extensions.end()) {
            mat.emissiveStrength = number(e->second.Get("emissiveStrength"), 1.0);
            if (!(mat.emissiveStrength >= 0.0f) || !std::isfinite(mat.emissiveStrength))
                fail(at + ".extensions.KHR_materials_emissive_strength.emissiveStrength", "must be finite and >= 0");
        }
        mat.emissiveTexture = textureIndex(m.emissiveTexture.index, at + ".emissiveTexture.index");
        mat.normalTexture = textureIndex(m.normalTexture.index, at + ".normalTexture.index");
        mat.normalScale = float(m.normalTexture.scale);
        for (auto [tc, key] : {std::pair{pbr.baseColorTexture.texCoord, "pbrMetallicRoughness.baseColorTexture"},
                               std::pair{m.emissiveTexture.texCoord, "emissiveTexture"},
                               std::pair{m.normalTexture.texCoord, "normalTexture"}})
            if (tc != 0) warn(at + "." + key + ".texCoord " + std::to_string(tc) + ": Kiln reads TEXCOORD_0");
        if (m.alphaMode == "OPAQUE" || m.alphaMode.empty()) mat.alphaMode = AlphaMode::Opaque;
        else if (m.alphaMode == "MASK") mat.alphaMode = AlphaMode::Mask;
        else if (m.alphaMode == "BLEND") {
            mat.alphaMode = AlphaMode::Blend;
            warn(at + ".alphaMode BLEND: drawn opaque");
        } else
            fail(at + ".alphaMode", "\"" + m.alphaMode + "\" is not OPAQUE, MASK or BLEND");
        mat.alphaCutoff = float(m.alphaCutoff);
        if (!(mat.alphaCutoff >= 0.0f) || !std::isfinite(mat.alphaCutoff)) fail(at + ".alphaCutoff", "must be >= 0");
        mat.doubleSided = m.doubleSided;
        out_.materials.push_back(mat);
    }

    // An accessor read as floats (normalized integers mapped to [0,1] or [-1,1]), its
    // bounds against its buffer view and buffer checked first.
    struct Read {
        std::vector<float> values;  // count × components
        int components = 0;
        size_t count = 0;
    };

    const uint8_t* viewData(int viewIndex, size_t offset, size_t count, size_t elementBytes, size_t& stride,
                            const std::string& at) {
        if (viewIndex < 0 || size_t(viewIndex) >= g_.bufferViews.size())
            fail(at + ".bufferView", "buffer view " + std::to_string(viewIndex) + " beyond the file's " +
                                         std::to_string(g_.bufferViews.size()));
        const tinygltf::BufferView& view = g_.bufferViews[size_t(viewIndex)];
        const std::string vat = idx("bufferViews", size_t(viewIndex));
        if (view.buffer < 0 || size_t(view.buffer) >= g_.buffers.size())
            fail(vat + ".buffer", "buffer " + std::to_string(view.buffer) + " beyond the file's " +
                                      std::to_string(g_.buffers.size()));
        const tinygltf::Buffer& buffer = g_.buffers[size_t(view.buffer)];
        if (view.byteOffset > buffer.data.size() || view.byteLength > buffer.data.size() - view.byteOffset)
            fail(vat, "bytes " + std::to_string(view.byteOffset) + " to " +
                          std::to_string(view.byteOffset + view.byteLength) + " beyond the " +
                          std::to_string(buffer.data.size()) + " bytes of buffers[" + std::to_string(view.buffer) + "]");
        stride = view.byteStride ? view.byteStride : elementBytes;
        if (stride < elementBytes)
            fail(vat + ".byteStride", std::to_string(view.byteStride) + " is less than the element's " +
                                          std::to_string(elementBytes) + " bytes (" + at + ")");
        if (count > 0) {
            const uint64_t need = uint64_t(offset) + uint64_t(stride) * (count - 1) + elementBytes;
            if (need > view.byteLength)
                fail(at, std::to_string(count) + " elements from byte " + std::to_string(offset) + " need " +
                             std::to_string(need) + " bytes, beyond the " + std::to_string(view.byteLength) +
                             " of bufferViews[" + std::to_string(viewIndex) + "]");
        }
        return buffer.data.data() + view.byteOffset;
    }

    static float component(const uint8_t* p, int type, bool normalized) {
        switch (type) {
            case TINYGLTF_COMPONENT_TYPE_FLOAT: { float f; std::memcpy(&f, p, 4); return f; }
            case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return normalized ? float(*p) / 255.0f : float(*p);
            case TINYGLTF_COMPONENT_TYPE_BYTE: {
                const float v = float(int8_t(*p));
                return normalized ? std::max(v / 127.0f, -1.0f) : v;
            }
            case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
                uint16_t u; std::memcpy(&u, p, 2);
                return normalized ? float(u) / 65535.0f : float(u);
            }
            case TINYGLTF_COMPONENT_TYPE_SHORT: {
                int16_t s; std::memcpy(&s, p, 2);
                return normalized ? std::max(float(s) / 32767.0f, -1.0f) : float(s);
            }
            case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: { uint32_t u; std::memcpy(&u, p, 4); return float(u); }
        }
        return 0.0f;
    }

    Read readAccessor(int index, const std::string& usedAt, std::initializer_list<int> types, int components) {
        if (index < 0 || size_t(index) >= g_.accessors.size())
            fail(usedAt, "accessor " + std::to_string(index) + " beyond the file's " + std::to_string(g_.accessors.size()));
        const tinygltf::Accessor& a = g_.accessors[size_t(index)];
        const std::string at = idx("accessors", size_t(index));
        if (componentCount(a.type) != components)
            fail(usedAt, at + " has " + std::to_string(componentCount(a.type)) + " components an element, " +
                             std::to_string(components) + " expected");
        if (std::find(types.begin(), types.end(), a.componentType) == types.end())
            fail(usedAt, at + " is " + componentName(a.componentType) + ", which this attribute cannot be");
        if (a.count > limits_.vertices * 3)
            fail(at + ".count", std::to_string(a.count) + " elements, over the limit");
        Read r;
        r.components = components;
        r.count = a.count;
        r.values.assign(a.count * size_t(components), 0.0f);
        const size_t cb = size_t(componentBytes(a.componentType));
        const size_t elementBytes = cb * size_t(components);
        if (a.byteOffset % cb != 0) fail(at + ".byteOffset", "not a multiple of the component's size");
        if (a.bufferView >= 0) {
            size_t stride = 0;
            const uint8_t* base = viewData(a.bufferView, a.byteOffset, a.count, elementBytes, stride, at);
            for (size_t e = 0; e < a.count; ++e)
                for (int c = 0; c < components; ++c)
                    r.values[e * size_t(components) + size_t(c)] =
                        component(base + a.byteOffset + e * stride + size_t(c) * cb, a.componentType, a.normalized);
        }
        if (a.sparse.isSparse) {
            const auto& sp = a.sparse;
            const std::string sat = at + ".sparse";
            if (sp.count < 0 || size_t(sp.count) > a.count) fail(sat + ".count", "more substitutions than elements");
            const int it = sp.indices.componentType;
            if (it != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE && it != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
                it != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT)
                fail(sat + ".indices.componentType", "must be an unsigned integer type");
            size_t istride = 0, vstride = 0;
            const uint8_t* ib = viewData(sp.indices.bufferView, size_t(sp.indices.byteOffset), size_t(sp.count),
                                         size_t(componentBytes(it)), istride, sat + ".indices");
            const uint8_t* vb = viewData(sp.values.bufferView, size_t(sp.values.byteOffset), size_t(sp.count),
                                         elementBytes, vstride, sat + ".values");
            istride = size_t(componentBytes(it)), vstride = elementBytes;  // sparse data is tightly packed
            for (size_t s = 0; s < size_t(sp.count); ++s) {
                const size_t target = size_t(component(ib + size_t(sp.indices.byteOffset) + s * istride, it, false));
                if (target >= a.count)
                    fail(sat + ".indices", "index " + std::to_string(target) + " beyond the accessor's " +
                                               std::to_string(a.count) + " elements");
                for (int c = 0; c < components; ++c)
                    r.values[target * size_t(components) + size_t(c)] = component(
                        vb + size_t(sp.values.byteOffset) + s * vstride + size_t(c) * cb, a.componentType, a.normalized);
            }
        }
        for (size_t v = 0; v < r.values.size(); ++v)
            if (!std::isfinite(r.values[v]))
                fail(usedAt, at + " element " + std::to_string(v / size_t(components)) + " is not finite");
        return r;
    }

    void readMesh(size_t meshIndex) {
        const tinygltf::Mesh& mesh = g_.meshes[meshIndex];
        for (size_t p = 0; p < mesh.primitives.size(); ++p) {
            const tinygltf::Primitive& prim = mesh.primitives[p];
            const std::string at = idx("meshes", meshIndex) + "." + idx("primitives", p);
            if (prim.mode < 4) {
                warn(at + ": points and lines are not drawn");
                continue;
            }
            if (prim.mode > 6) fail(at + ".mode", std::to_string(prim.mode) + " is not a primitive mode (0 to 6)");
            if (!prim.targets.empty()) warn(at + ": morph targets are ignored (drawn at rest)");
            auto pos = prim.attributes.find("POSITION");
            if (pos == prim.attributes.end()) {
                warn(at + " has no POSITION: not drawn");
                continue;
            }
            if (prim.material >= 0 && size_t(prim.material) >= g_.materials.size())
                fail(at + ".material", "material " + std::to_string(prim.material) + " beyond the file's " +
                                           std::to_string(g_.materials.size()));
            Mesh out;
            out.name = (mesh.name.empty() ? idx("meshes", meshIndex) : mesh.name) + "/" + std::to_string(p);
            out.material = prim.material;
            const Read positions = readAccessor(pos->second, at + ".attributes.POSITION", {TINYGLTF_COMPONENT_TYPE_FLOAT,
                TINYGLTF_COMPONENT_TYPE_BYTE, TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE, TINYGLTF_COMPONENT_TYPE_SHORT,
                TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT}, 3);
            const size_t n = positions.count;
            if (n == 0) {
                warn(at + ": no vertices");
                continue;
            }
            totalVertices_ += n;
            if (totalVertices_ > limits_.vertices)
                fail(at + ".attributes.POSITION", "the meshes' vertices pass the limit of " +
                                                      std::to_string(limits_.vertices));
            out.vertices.resize(n);
            for (size_t v = 0; v < n; ++v)
                out.vertices[v].position = glm::make_vec3(&positions.values[v * 3]);
            auto same = [&](const Read& r, const char* name) {
                if (r.count != n)
                    fail(at + ".attributes." + name, std::to_string(r.count) + " elements where POSITION has " +
                                                         std::to_string(n));
            };
            bool hasNormals = false;
            if (auto it = prim.attributes.find("NORMAL"); it != prim.attributes.end()) {
                const Read normals = readAccessor(it->second, at + ".attributes.NORMAL", {TINYGLTF_COMPONENT_TYPE_FLOAT,
                    TINYGLTF_COMPONENT_TYPE_BYTE, TINYGLTF_COMPONENT_TYPE_SHORT}, 3);
                same(normals, "NORMAL");
                for (size_t v = 0; v < n; ++v) {
                    const glm::vec3 nrm = glm::make_vec3(&normals.values[v * 3]);
                    const float len = glm::length(nrm);
                    if (!(len > 0.5f && len < 1.5f))
                        fail(at + ".attributes.NORMAL", "element " + std::to_string(v) + " has length " +
                                                            std::to_string(len) + " (a normal is a unit vector)");
                    out.vertices[v].normal = nrm / len;
                }
                hasNormals = true;
            }
            bool hasUv = false;
            if (auto it = prim.attributes.find("TEXCOORD_0"); it != prim.attributes.end()) {
                const Read uvs = readAccessor(it->second, at + ".attributes.TEXCOORD_0", {TINYGLTF_COMPONENT_TYPE_FLOAT,
                    TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE, TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT}, 2);
                same(uvs, "TEXCOORD_0");
                for (size_t v = 0; v < n; ++v) out.vertices[v].uv = glm::make_vec2(&uvs.values[v * 2]);
                hasUv = true;
            }
            bool hasTangents = false;
            if (auto it = prim.attributes.find("TANGENT"); it != prim.attributes.end()) {
                const Read t = readAccessor(it->second, at + ".attributes.TANGENT", {TINYGLTF_COMPONENT_TYPE_FLOAT,
                    TINYGLTF_COMPONENT_TYPE_BYTE, TINYGLTF_COMPONENT_TYPE_SHORT}, 4);
                same(t, "TANGENT");
                for (size_t v = 0; v < n; ++v) {
                    glm::vec4 tv = glm::make_vec4(&t.values[v * 4]);
                    const float len = glm::length(glm::vec3(tv));
                    tv = len > 1e-6f ? glm::vec4(glm::vec3(tv) / len, tv.w < 0.0f ? -1.0f : 1.0f)
                                     : glm::vec4(1.0f, 0.0f, 0.0f, 1.0f);
                    out.vertices[v].tangent = tv;
                }
                hasTangents = true;
            }
            std::vector<uint32_t> indices;
            if (prim.indices >= 0) {
                const Read ix = readAccessor(prim.indices, at + ".indices", {TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE,
                    TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT, TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT}, 1);
                indices.resize(ix.count);
                for (size_t i = 0; i < ix.count; ++i) {
                    const double value = double(ix.values[i]);
                    if (value >= double(n))
                        fail(at + ".indices", "index " + std::to_string(uint64_t(value)) + " (element " +
                                                  std::to_string(i) + ") beyond the " + std::to_string(n) +
                                                  " vertices of attributes.POSITION");
                    indices[i] = uint32_t(value);
                }
                // An UNSIGNED_INT above 2^24 does not survive the float read exactly: re-read it.
                const tinygltf::Accessor& a = g_.accessors[size_t(prim.indices)];
                if (a.componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT && n > (1u << 24) && a.bufferView >= 0) {
                    size_t stride = 0;
                    const uint8_t* base = viewData(a.bufferView, a.byteOffset, a.count, 4, stride, idx("accessors", size_t(prim.indices)));
                    for (size_t i = 0; i < a.count; ++i) std::memcpy(&indices[i], base + a.byteOffset + i * stride, 4);
                }
            } else {
                indices.resize(n);
                for (size_t i = 0; i < n; ++i) indices[i] = uint32_t(i);
            }
            out.indices = triangulate(indices, prim.mode, at, prim.indices >= 0);
            if (out.indices.empty()) {
                warn(at + ": no whole triangle");
                continue;
            }
            const bool normalMapped = prim.material >= 0 && g_.materials[size_t(prim.material)].normalTexture.index >= 0;
            if (!hasNormals) flatNormals(out);
            if (normalMapped && !hasTangents) {
                if (!hasUv) warn(at + ": a normal map without TEXCOORD_0: drawn without it");
                else generateTangents(out);
            }
            optimizeForDrawing(out);
            meshPrimitives_[meshIndex].push_back(int(out_.meshes.size()));
            out.boundsMin = out.boundsMax = out.vertices[0].position;
            for (const Vertex& v : out.vertices) {
                out.boundsMin = glm::min(out.boundsMin, v.position);
                out.boundsMax = glm::max(out.boundsMax, v.position);
            }
            out_.meshes.push_back(std::move(out));
        }
    }

    static std::vector<uint32_t> triangulate(const std::vector<uint32_t>& in, int mode, const std::string& at,
                                             bool indexed) {
        std::vector<uint32_t> out;
        if (mode == TINYGLTF_MODE_TRIANGLES) {
            if (in.size() % 3 != 0)
                fail(indexed ? at + ".indices" : at + ".attributes.POSITION",
                     std::to_string(in.size()) + (indexed ? " indices" : " vertices (no indices)") +
                         " for TRIANGLES: not a multiple of 3");
            out.assign(in.begin(), in.begin() + ptrdiff_t(in.size() / 3 * 3));
        } else if (mode == TINYGLTF_MODE_TRIANGLE_STRIP) {
            for (size_t i = 2; i < in.size(); ++i) {
                if (i % 2 == 0) out.insert(out.end(), {in[i - 2], in[i - 1], in[i]});
                else out.insert(out.end(), {in[i - 1], in[i - 2], in[i]});
            }
        } else if (mode == TINYGLTF_MODE_TRIANGLE_FAN) {
            for (size_t i = 2; i < in.size(); ++i) out.insert(out.end(), {in[0], in[i - 1], in[i]});
        }
        return out;
    }

    // Triangles in the order a post-transform vertex cache reuses best, then vertices in
    // the order the triangles first use them (meshoptimizer): a CPU rasterizer's vertex
    // stage is most of a large mesh's cost.
    static void optimizeForDrawing(Mesh& m) {
        meshopt_optimizeVertexCache(m.indices.data(), m.indices.data(), m.indices.size(), m.vertices.size());
        std::vector<Vertex> vertices(m.vertices.size());
        const size_t used = meshopt_optimizeVertexFetch(vertices.data(), m.indices.data(), m.indices.size(),
                                                        m.vertices.data(), m.vertices.size(), sizeof(Vertex));
        vertices.resize(used);
        m.vertices = std::move(vertices);
    }

    // glTF: without NORMAL, flat normals. Each triangle gets vertices of its own.
    static void flatNormals(Mesh& m) {
        std::vector<Vertex> vertices;
        vertices.reserve(m.indices.size());
        for (size_t t = 0; t + 2 < m.indices.size(); t += 3) {
            Vertex a = m.vertices[m.indices[t]], b = m.vertices[m.indices[t + 1]], c = m.vertices[m.indices[t + 2]];
            glm::vec3 n = glm::cross(b.position - a.position, c.position - a.position);
            const float len = glm::length(n);
            n = len > 0.0f && std::isfinite(len) ? n / len : glm::vec3(0.0f, 1.0f, 0.0f);
            a.normal = b.normal = c.normal = n;
            vertices.insert(vertices.end(), {a, b, c});
        }
        m.vertices = std::move(vertices);
        for (size_t i = 0; i < m.indices.size(); ++i) m.indices[i] = uint32_t(i);
    }

    // Per-vertex tangents from the UV gradients of the triangles around each vertex
    // (Lengyel's accumulation, orthogonalised against the normal). glTF asks for
    // MikkTSpace; the two agree on meshes whose UV charts have no seams inside a face.
    static void generateTangents(Mesh& m) {
        std::vector<glm::vec3> tan(m.vertices.size(), glm::vec3(0.0f)), bit(m.vertices.size(), glm::vec3(0.0f));
        for (size_t t = 0; t + 2 < m.indices.size(); t += 3) {
            const uint32_t i0 = m.indices[t], i1 = m.indices[t + 1], i2 = m.indices[t + 2];
            const Vertex &a = m.vertices[i0], &b = m.vertices[i1], &c = m.vertices[i2];
            const glm::vec3 e1 = b.position - a.position, e2 = c.position - a.position;
            const glm::vec2 d1 = b.uv - a.uv, d2 = c.uv - a.uv;
            const float det = d1.x * d2.y - d2.x * d1.y;
            if (std::abs(det) < 1e-12f) continue;
            const float r = 1.0f / det;
            const glm::vec3 s = (e1 * d2.y - e2 * d1.y) * r, u = (e2 * d1.x - e1 * d2.x) * r;
            for (uint32_t i : {i0, i1, i2}) tan[i] += s, bit[i] += u;
        }
        for (size_t v = 0; v < m.vertices.size(); ++v) {
            const glm::vec3 n = m.vertices[v].normal;
            glm::vec3 t = tan[v] - n * glm::dot(n, tan[v]);
            const float len = glm::length(t);
            if (!(len > 1e-8f)) {
                t = std::abs(n.x) < 0.9f ? glm::normalize(glm::cross(n, glm::vec3(1, 0, 0)))
                                         : glm::normalize(glm::cross(n, glm::vec3(0, 1, 0)));
            } else {
                t /= len;
            }
            const float w = glm::dot(glm::cross(n, t), bit[v]) < 0.0f ? -1.0f : 1.0f;
            m.vertices[v].tangent = glm::vec4(t, w);
        }
    }

    void checkLight(size_t i) {
        const tinygltf::Light& l = g_.lights[i];
        const std::string at = "extensions.KHR_lights_punctual." + idx("lights", i);
        Light light;
        light.name = l.name.empty() ? at : l.name;
        if (l.type == "directional") light.type = Light::Type::Directional;
        else if (l.type == "point") light.type = Light::Type::Point;
        else if (l.type == "spot") light.type = Light::Type::Spot;
        else fail(at + ".type", "\"" + l.type + "\" is not directional, point or spot");
        if (!l.color.empty()) {
            if (l.color.size() != 3) fail(at + ".color", "expected 3 numbers");
            light.color = glm::vec3(float(l.color[0]), float(l.color[1]), float(l.color[2]));
        }
        if (!finite(light.color) || glm::any(glm::lessThan(light.color, glm::vec3(0.0f))))
            fail(at + ".color", "must be finite and >= 0");
        light.intensity = float(l.intensity);
        if (!(light.intensity >= 0.0f) || !std::isfinite(light.intensity)) fail(at + ".intensity", "must be finite and >= 0");
        light.range = float(l.range);
        if (!(light.range >= 0.0f) || !std::isfinite(light.range)) fail(at + ".range", "must be finite and >= 0");
        light.innerCone = float(l.spot.innerConeAngle);
        light.outerCone = float(l.spot.outerConeAngle);
        if (light.type == Light::Type::Spot &&
            !(light.innerCone >= 0.0f && light.innerCone < light.outerCone && light.outerCone <= 1.5707964f))
            fail(at + ".spot", "needs 0 <= innerConeAngle < outerConeAngle <= pi/2");
        lights_.push_back(light);
    }

    glm::mat4 localTransform(const tinygltf::Node& node, const std::string& at) {
        glm::mat4 m(1.0f);
        if (!node.matrix.empty()) {
            if (node.matrix.size() != 16) fail(at + ".matrix", "expected 16 numbers, got " + std::to_string(node.matrix.size()));
            for (int c = 0; c < 16; ++c) m[c / 4][c % 4] = float(node.matrix[size_t(c)]);
            return m;
        }
        glm::vec3 t(0.0f), s(1.0f);
        glm::quat r(1.0f, 0.0f, 0.0f, 0.0f);
        if (!node.translation.empty()) {
            if (node.translation.size() != 3) fail(at + ".translation", "expected 3 numbers");
            t = glm::vec3(float(node.translation[0]), float(node.translation[1]), float(node.translation[2]));
        }
        if (!node.rotation.empty()) {
            if (node.rotation.size() != 4) fail(at + ".rotation", "expected 4 numbers (a quaternion x, y, z, w)");
            r = glm::quat(float(node.rotation[3]), float(node.rotation[0]), float(node.rotation[1]), float(node.rotation[2]));
            const float len = glm::length(r);
            if (!(len > 1e-6f)) fail(at + ".rotation", "a zero quaternion");
            r /= len;
        }
        if (!node.scale.empty()) {
            if (node.scale.size() != 3) fail(at + ".scale", "expected 3 numbers");
            s = glm::vec3(float(node.scale[0]), float(node.scale[1]), float(node.scale[2]));
        }
        return glm::translate(glm::mat4(1.0f), t) * glm::mat4_cast(r) * glm::scale(glm::mat4(1.0f), s);
    }

    void readNodes() {
        // Each node has at most one parent: glTF's node hierarchy is a set of trees.
        std::vector<int> parent(g_.nodes.size(), -1);
        for (size_t i = 0; i < g_.nodes.size(); ++i)
            for (size_t c = 0; c < g_.nodes[i].children.size(); ++c) {
                const int child = g_.nodes[i].children[c];
                const std::string at = idx("nodes", i) + "." + idx("children", c);
                if (child < 0 || size_t(child) >= g_.nodes.size())
                    fail(at, "node " + std::to_string(child) + " beyond the file's " + std::to_string(g_.nodes.size()));
                if (size_t(child) == i) fail(at, "the node is its own child");
                if (parent[size_t(child)] >= 0)
                    fail(at, "node " + std::to_string(child) + " already has a parent, nodes[" +
                                 std::to_string(parent[size_t(child)]) + "] (a node hierarchy is a tree)");
                parent[size_t(child)] = int(i);
            }
        std::vector<int> roots;
        if (!g_.scenes.empty()) {
            int scene = g_.defaultScene;
            if (scene >= 0 && size_t(scene) >= g_.scenes.size())
                fail("scene", "scene " + std::to_string(scene) + " beyond the file's " + std::to_string(g_.scenes.size()));
            if (scene < 0) scene = 0;
            sceneName_ = idx("scenes", size_t(scene));
            const auto& nodes = g_.scenes[size_t(scene)].nodes;
            for (size_t k = 0; k < nodes.size(); ++k) {
                if (nodes[k] < 0 || size_t(nodes[k]) >= g_.nodes.size())
                    fail(sceneName_ + "." + idx("nodes", k), "node " + std::to_string(nodes[k]) + " beyond the file's " +
                                                                std::to_string(g_.nodes.size()));
                if (parent[size_t(nodes[k])] >= 0)
                    fail(sceneName_ + "." + idx("nodes", k), "node " + std::to_string(nodes[k]) +
                                                                " is a child of nodes[" +
                                                                std::to_string(parent[size_t(nodes[k])]) +
                                                                "]: a scene lists root nodes");
                roots.push_back(nodes[k]);
            }
        } else {
            if (g_.defaultScene >= 0) fail("scene", "scene " + std::to_string(g_.defaultScene) + " but the file has no scenes");
            // No scene: glTF leaves it to the viewer; Kiln draws every root node.
            for (size_t i = 0; i < g_.nodes.size(); ++i)
                if (parent[i] < 0) roots.push_back(int(i));
            if (!g_.nodes.empty()) warn("no scene: every root node is drawn");
        }
        // Trees without cycles: a cycle has no root, so a node never reached from a root
        // is on one (or under one).
        std::vector<char> visited(g_.nodes.size(), 0);
        std::function<void(int, const glm::mat4&, int)> visit = [&](int n, const glm::mat4& parentWorld, int depth) {
            const std::string at = idx("nodes", size_t(n));
            if (depth > limits_.nodeDepth)
                fail(at, "nested more than " + std::to_string(limits_.nodeDepth) + " deep");
            visited[size_t(n)] = 1;
            const tinygltf::Node& node = g_.nodes[size_t(n)];
            const glm::mat4 world = parentWorld * localTransform(node, at);
            for (int c = 0; c < 4; ++c)
                if (!finite(glm::vec3(world[c])) || !std::isfinite(world[c][3])) fail(at, "its transform is not finite");
            if (node.skin >= 0) warn(at + ": skins are ignored (drawn in the bind pose)");
            if (node.mesh >= 0) {
                if (size_t(node.mesh) >= g_.meshes.size())
                    fail(at + ".mesh", "mesh " + std::to_string(node.mesh) + " beyond the file's " +
                                           std::to_string(g_.meshes.size()));
                for (int m : meshPrimitives_[size_t(node.mesh)]) {
                    if (out_.instances.size() >= limits_.instances)
                        fail(at + ".mesh", "more than " + std::to_string(limits_.instances) + " mesh instances");
                    triangles_ += out_.meshes[size_t(m)].indices.size() / 3;
                    if (triangles_ > limits_.triangles)
                        fail(at + ".mesh", "the scene's triangles pass the limit of " + std::to_string(limits_.triangles));
                    out_.instances.push_back({m, n, world});
                }
            }
            if (node.camera >= 0) {
                if (size_t(node.camera) >= g_.cameras.size())
                    fail(at + ".camera", "camera " + std::to_string(node.camera) + " beyond the file's " +
                                             std::to_string(g_.cameras.size()));
                readCamera(size_t(node.camera), world);
            }
            if (auto e = node.extensions.find("KHR_lights_punctual"); e != node.extensions.end()) {
                const tinygltf::Value& li = e->second.Get("light");
                if (!li.IsInt() || li.GetNumberAsInt() < 0 || size_t(li.GetNumberAsInt()) >= lights_.size())
                    fail(at + ".extensions.KHR_lights_punctual.light",
                         "expected a light index below " + std::to_string(lights_.size()));
                Light light = lights_[size_t(li.GetNumberAsInt())];
                light.position = glm::vec3(world[3]);
                const glm::vec3 d = glm::mat3(world) * glm::vec3(0.0f, 0.0f, -1.0f);
                if (!(glm::length(d) > 1e-8f)) fail(at, "a light's transform has no direction (scale 0)");
                light.direction = glm::normalize(d);
                out_.lights.push_back(light);
            }
            for (int child : node.children) visit(child, world, depth + 1);
        };
        for (int r : roots) visit(r, glm::mat4(1.0f), 0);
        for (size_t i = 0; i < g_.nodes.size(); ++i)
            if (!visited[i] && parent[i] >= 0) {
                // Reached from no root though it has a parent: it sits on a cycle or under
                // one (a root of a scene would have been reached).
                bool onCycle = false;
                for (size_t k = 0, n = i; k <= g_.nodes.size() && parent[n] >= 0; ++k) {
                    n = size_t(parent[n]);
                    if (n == i) onCycle = true;
                }
                if (onCycle) fail(idx("nodes", i) + ".children", "the node is its own ancestor (a cycle)");
            }
    }

    void readCamera(size_t i, const glm::mat4& world) {
        const tinygltf::Camera& c = g_.cameras[i];
        const std::string at = idx("cameras", i);
        if (c.type != "perspective") {
            warn(at + ": only perspective cameras are used");
            return;
        }
        Camera cam;
        cam.name = c.name.empty() ? at : c.name;
        // The camera's frame without scale: glTF says a camera's transform has none, and a
        // scaled one would distort the view.
        glm::mat4 t = world;
        for (int a = 0; a < 3; ++a) {
            const float len = glm::length(glm::vec3(t[a]));
            if (!(len > 1e-8f)) fail(at, "its node's transform has scale 0");
            t[a] = glm::vec4(glm::vec3(t[a]) / len, 0.0f);
        }
        cam.transform = t;
        cam.yfov = float(c.perspective.yfov);
        cam.aspect = float(c.perspective.aspectRatio);
        cam.znear = float(c.perspective.znear);
        cam.zfar = float(c.perspective.zfar);
        if (!(cam.yfov > 0.0f && cam.yfov < 3.14159f)) fail(at + ".perspective.yfov", "must lie in (0, pi)");
        if (!(cam.znear > 0.0f) || !std::isfinite(cam.znear)) fail(at + ".perspective.znear", "must be > 0");
        if (!(cam.zfar == 0.0f || cam.zfar > cam.znear) || !std::isfinite(cam.zfar))
            fail(at + ".perspective.zfar", "must be greater than znear");
        if (!(cam.aspect >= 0.0f) || !std::isfinite(cam.aspect)) fail(at + ".perspective.aspectRatio", "must be > 0");
        out_.cameras.push_back(cam);
    }

    void computeBounds() {
        bool any = false;
        for (const Instance& inst : out_.instances) {
            const Mesh& m = out_.meshes[size_t(inst.mesh)];
            for (int corner = 0; corner < 8; ++corner) {
                const glm::vec3 p((corner & 1) ? m.boundsMax.x : m.boundsMin.x, (corner & 2) ? m.boundsMax.y : m.boundsMin.y,
                                  (corner & 4) ? m.boundsMax.z : m.boundsMin.z);
                const glm::vec3 w = glm::vec3(inst.transform * glm::vec4(p, 1.0f));
                out_.boundsMin = any ? glm::min(out_.boundsMin, w) : w;
                out_.boundsMax = any ? glm::max(out_.boundsMax, w) : w;
                any = true;
            }
        }
        for (const Light& l : out_.lights)
            if (l.type != Light::Type::Directional && !any) out_.boundsMin = out_.boundsMax = l.position, any = true;
    }

    const tinygltf::Model& g_;
    const Limits& limits_;
    Model& out_;
    std::vector<std::vector<int>> meshPrimitives_;  // glTF mesh → its primitives in out_.meshes
    std::vector<Light> lights_;                     // the file's lights, placed by nodes
    std::string sceneName_ = "scenes[0]";
    uint64_t totalVertices_ = 0, triangles_ = 0;
};

std::string directoryOf(const std::string& path) {
    const size_t slash = path.find_last_of('/');
    return slash == std::string::npos ? std::string(".") : path.substr(0, slash);
}

// The JSON of a .gltf, or the JSON chunk of a .glb (checked only as far as it is read).
bool jsonText(const uint8_t* bytes, size_t size, bool& binary, std::string& json, std::string& error) {
    binary = size >= 4 && std::memcmp(bytes, "glTF", 4) == 0;
    if (!binary) {
        json.assign(reinterpret_cast<const char*>(bytes), size);
        return true;
    }
    if (size < 20) {
        error = "a .glb shorter than its 20-byte header";
        return false;
    }
    uint32_t version, length, chunkLength, chunkType;
    std::memcpy(&version, bytes + 4, 4);
    std::memcpy(&length, bytes + 8, 4);
    std::memcpy(&chunkLength, bytes + 12, 4);
    std::memcpy(&chunkType, bytes + 16, 4);
    if (version != 2) {
        error = "a .glb of container version " + std::to_string(version) + " (Kiln reads version 2)";
        return false;
    }
    if (length > size) {
        error = "the .glb header says " + std::to_string(length) + " bytes, the file has " + std::to_string(size);
        return false;
    }
    if (chunkType != 0x4E4F534Au || uint64_t(chunkLength) + 20 > length) {
        error = "the .glb's first chunk is not a JSON chunk within the file";
        return false;
    }
    json.assign(reinterpret_cast<const char*>(bytes + 20), chunkLength);
    return true;
}

// tinygltf's messages carry a trailing newline and sometimes several lines.
std::string oneLine(std::string s) {
    while (!s.empty() && (s.back() == '\n' || s.back() == ' ')) s.pop_back();
    for (char& c : s)
        if (c == '\n') c = ';';
    return s;
}

}  // namespace

bool loadGltfFromMemory(const std::string& name, const uint8_t* bytes, size_t size, const std::string& baseDir,
                        Model& out, std::string& error, const Limits& limits) {
    // One line of bounded length: a path or a message may quote what the file holds.
    auto say = [&](const std::string& path, const std::string& message) {
        error = name + ": " + (path.empty() ? "" : json_text::elide(path, 200) + ": ") + json_text::elide(message, 400);
        for (char& c : error)
            if (c == '\n' || c == '\r') c = ' ';
        return false;
    };
    if (size > limits.fileBytes)
        return say("", bytesText(size) + ", over the limit of " + bytesText(limits.fileBytes));
    bool binary = false;
    std::string json, why;
    if (!jsonText(bytes, size, binary, json, why)) return say("", why);
    nlohmann::json root;
    try {
        root = nlohmann::json::parse(json);
    } catch (const nlohmann::json::parse_error& e) {
        // nlohmann's message quotes all it read of the bad token: the line and column say where.
        int line = 1, column = 1;
        json_text::lineColumn(json, e.byte > 0 ? e.byte - 1 : 0, line, column);
        std::string what = e.what();
        if (const size_t cut = what.find("; last read"); cut != std::string::npos) what.resize(cut);
        if (const size_t colon = what.find(": syntax error"); colon != std::string::npos) what = what.substr(colon + 2);
        return say("", "not valid JSON: line " + std::to_string(line) + ", column " + std::to_string(column) + ": " + what);
    } catch (const nlohmann::json::exception& e) {
        return say("", std::string("not valid JSON: ") + e.what());
    }
    SchemaError schema;
    if (!checkGltfSchema(root, schema)) return say(schema.path, schema.message);

    LoadState state;
    state.limits = &limits;
    tinygltf::TinyGLTF loader;
    loader.SetImageLoader(&loadImage, &state);
    tinygltf::FsCallbacks fs{&fileExists, &expandPath, &readWholeFile, &writeWholeFile, &state};
    loader.SetFsCallbacks(fs);
    tinygltf::Model g;
    std::string err, warn;
    const std::string base = baseDir.empty() ? std::string("/nonexistent-kiln-base") : baseDir;
    const bool ok = binary ? loader.LoadBinaryFromMemory(&g, &err, &warn, bytes, unsigned(size), base)
                           : loader.LoadASCIIFromString(&g, &err, &warn, json.data(), unsigned(json.size()), base);
    if (!ok) {
        // Name the buffer or image whose file could not be read, by its JSON path.
        if (state.fsError.empty() && err.find("File not found") != std::string::npos) state.fsError = oneLine(err);
        if (!state.fsError.empty()) {
            for (const char* array : {"buffers", "images"})
                if (root.contains(array))
                    for (size_t i = 0; i < root[array].size(); ++i) {
                        const std::string uri = root[array][i].value("uri", "");
                        if (!uri.empty() && uri.rfind("data:", 0) != 0 &&
                            state.fsError.find(uri) != std::string::npos)
                            return say(idx(array, i) + ".uri", "cannot read " + state.fsError);
                    }
            return say("", "cannot read " + state.fsError);
        }
        return say("", oneLine(err.empty() ? "tinygltf could not load it" : err));
    }
    Model model;
    try {
        Builder(g, limits, model).build();
    } catch (const LoadError& e) {
        return say(e.path, e.message);
    }
    model.files = std::move(state.files);
    out = std::move(model);
    return true;
}

bool loadGltf(const std::string& path, Model& out, std::string& error, const Limits& limits) {
    struct stat st{};
    if (::stat(path.c_str(), &st) != 0 || !S_ISREG(st.st_mode)) {
        error = path + ": cannot read (no such file)";
        return false;
    }
    if (size_t(st.st_size) > limits.fileBytes) {
        error = path + ": " + bytesText(size_t(st.st_size)) + ", over the limit of " + bytesText(limits.fileBytes);
        return false;
    }
    std::ifstream in(path, std::ios::binary);
    std::vector<uint8_t> bytes(size_t(st.st_size));
    if (!in.read(reinterpret_cast<char*>(bytes.data()), std::streamsize(bytes.size()))) {
        error = path + ": cannot read";
        return false;
    }
    if (!loadGltfFromMemory(path, bytes.data(), bytes.size(), directoryOf(path), out, error, limits)) return false;
    out.files.insert(out.files.begin(), path);
    return true;
}

}  // namespace kiln::model
