// kiln/declare.hpp — what a pass *declares*: inputs, outputs, internal textures,
// parameters and the scene categories it reads.
//
// This half of the pass ABI has no OpenGL in it, so the graph compiler (and its
// tests) can validate a pipeline against declarations without a GL context. Pass
// authors read the manual at the top of kiln/pass.hpp; this file is included from there.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <variant>
#include <vector>

namespace kiln {

// Texture shapes a slot can hold. Depth is its own kind because a depth texture
// cannot be bound where a colour texture is expected (and vice versa).
enum class TextureKind : uint8_t { Color2D, Depth2D, Color3D };

enum class Format : uint8_t {
    RGBA8,      // albedo, LDR final image
    RGBA16F,    // HDR colour, radiance
    RGBA32F,
    RG16F,
    R16F,
    R32F,
    R11G11B10F,
    R32UI,      // atomics (voxel accumulation)
    Depth32F,
    Depth24,
};

const char* toString(TextureKind);
const char* toString(Format);
bool isDepthFormat(Format);
// Parses "rgba16f", "depth32f", ...; returns false on an unknown name.
bool parseFormat(const std::string& name, Format& out);

// What an optional input reads when nothing is bound to it. The shader also sees
// `#define KILN_HAS_<INPUT> 0`, so it can skip the fetch altogether.
enum class Fallback : uint8_t { Black, White, FlatNormal, FarDepth };
const char* toString(Fallback);

// How big an output or internal texture is.
struct SizeRule {
    enum class Mode : uint8_t {
        RelativeToOutput,  // scale × the graph's output size (2D)
        Fixed,             // width × height (× depth for 3D)
        FromParam,         // a square (2D) or cube (3D) whose side is an int parameter × scale;
                           // `tiles` such blocks side by side along x (a slab atlas)
        FromInput,         // the size of what is bound to input `source` (× scale per side;
                           // 1×1(×1) when an optional input is unbound); `tiles` such
                           // blocks side by side along x
        RelativeOverParam, // scale × the graph's output size ÷ the int parameter `source`
                           // (2D; e.g. a trace at 1/stride of the picture), the divisor
                           // raised where `capSource` caps the samples across (sizeDivisor)
    };
    Mode mode = Mode::RelativeToOutput;
    float scale = 1.0f;
    int width = 0, height = 0, depth = 1;
    std::string source;  // FromParam: the int parameter; FromInput: the input slot
    int tiles = 1;
    std::string capSource;  // RelativeOverParam: an int parameter, the most texels across
                            // the longer side (≤ 0: no cap)

    static SizeRule relative(float s = 1.0f) { return {Mode::RelativeToOutput, s, 0, 0, 1, {}, 1}; }
    static SizeRule fixed(int w, int h, int d = 1) { return {Mode::Fixed, 1.0f, w, h, d, {}, 1}; }
    static SizeRule fromParam(std::string name, float scale = 1.0f, int tiles = 1) {
        return {Mode::FromParam, scale, 0, 0, 1, std::move(name), tiles};
    }
    static SizeRule fromInput(std::string slot, float scale = 1.0f, int tiles = 1) {
        return {Mode::FromInput, scale, 0, 0, 1, std::move(slot), tiles};
    }
    static SizeRule relativeOverParam(std::string name, float scale = 1.0f, std::string cap = {}) {
        return {Mode::RelativeOverParam, scale, 0, 0, 1, std::move(name), 1, std::move(cap)};
    }
};

// The divisor of a RelativeOverParam size at an outW × outH output: the parameter's
// value, or, where a cap is given (> 0), at least ⌈longer side ÷ cap⌉, so no more than
// about `cap` texels lie across however large the picture (a trace whose density is
// set in samples across the view, not in a fraction of its pixels). A pass that reads
// the divisor back (its stride) calls this with the same values the host sized by.
inline int sizeDivisor(int divisor, int cap, int outW, int outH) {
    divisor = divisor < 1 ? 1 : divisor;
    if (cap <= 0) return divisor;
    const int longer = outW > outH ? outW : outH;
    const int capped = (longer + cap - 1) / cap;
    return capped > divisor ? capped : divisor;
}

// Mip count 1 = no mips; kFullMipChain = down to 1×1(×1).
inline constexpr int kFullMipChain = 0;

struct InputDecl {
    std::string name;
    TextureKind kind = TextureKind::Color2D;
    bool required = true;
    Fallback fallback = Fallback::Black;  // used only when !required and unbound
    std::string doc;
};

// An output that only some values of one enum parameter fill (voxel_mip's chains, by
// mode). Binding it while the parameter has another value is a pipeline error naming
// the values that fill it, not a black texture. Empty `param`: always filled.
struct ProducedWhen {
    std::string param;
    std::vector<std::string> values;
};

struct TextureDecl {  // an output (bindable by later passes) or an internal texture
    std::string name;
    TextureKind kind = TextureKind::Color2D;
    Format format = Format::RGBA16F;
    SizeRule size = SizeRule::relative();
    int mips = 1;
    std::string doc;
    // Depth written through a perspective projection: its near and far planes, so a
    // viewer can show linear distance (both 0: orthographic or unknown, shown as stored).
    float depthNear = 0.0f, depthFar = 0.0f;
    ProducedWhen producedWhen;  // outputs only
    // Outputs only: the pass leaves it unwritten while nothing reads it
    // (PassContext::isRead), so what it holds then is stale; the debug view says so.
    bool onlyWhenRead = false;
};

enum class ParamType : uint8_t { Bool, Int, Float, Enum, Color };
const char* toString(ParamType);

using Color3 = std::array<float, 3>;
using ParamValue = std::variant<bool, int, float, std::string, Color3>;

struct ParamDecl {
    std::string name;
    ParamType type = ParamType::Float;
    ParamValue def = 0.0f;
    double min = 0.0, max = 0.0;          // Int/Float; min == max means unbounded
    std::vector<std::string> choices;     // Enum; for Int, a non-empty list of allowed values
    std::vector<int> intChoices;          //   (e.g. cone count 1, 5, 6, 9, 16)
    std::string doc;
};

// Parts of the scene model. One set of bits serves two purposes: a pass's `reads` (the
// host re-runs it only when one of these, its inputs or its parameters changed, unless
// it is time-dependent) and drawScene()'s filter (the geometry bits). Geometry comes in
// static parts (planes, the area light's surface, placed meshes) and moving bodies of
// three shapes; a scene source fills whichever it has and leaves the rest empty.
enum SceneCategory : uint32_t {
    kSceneNone = 0,
    kScenePlanes = 1u << 0,        // static quads (unit squares placed by their model), each
                                   //   a plain albedo or the procedural rings material
    kSceneLightSurface = 1u << 1,  // the spherical area light's visible surface (a cap)
    kSceneMeshes = 1u << 2,        // static triangle meshes (glTF models), with their
                                   //   materials and textures (SceneView::materialTextures)
    kSceneRoundCones = 1u << 3,    // moving round cones (GpuFrame::roundCone), shadow casters
    kSceneSpheres = 1u << 4,       // moving spheres, shadow casters
    kSceneGlowingSpheres = 1u << 5,  // moving emissive spheres: they emit, they cast no shadow
    kSceneParticles = 1u << 6,     // point emitters, drawn as small spheres
    kSceneLights = 1u << 7,        // the area light's position, size and radiance; the
                                   //   punctual lights
    kSceneCamera = 1u << 8,
    kSceneTime = 1u << 9,

    kSceneStatic = kScenePlanes | kSceneLightSurface,
    kSceneBodies = kSceneRoundCones | kSceneSpheres | kSceneGlowingSpheres,
    kSceneShadowCasters = kSceneRoundCones | kSceneSpheres,  // the moving casters
    kSceneGeometry = 0x7f,      // what drawScene() can draw
    kSceneAll = 0x3ff,
};
inline constexpr int kSceneCategoryCount = 10;
inline constexpr int kSceneGeometryCount = 7;

struct PassDeclaration {
    std::vector<InputDecl> inputs;
    std::vector<TextureDecl> outputs;
    std::vector<TextureDecl> internals;
    std::vector<ParamDecl> params;
    uint32_t reads = kSceneNone;        // SceneCategory bits (kSceneBodies | kSceneCamera, ...)
    bool timeDependent = false;         // run every frame regardless of versions

    // Fluent helpers so a pass's declare() reads like a table.
    PassDeclaration& input(InputDecl d) { inputs.push_back(std::move(d)); return *this; }
    PassDeclaration& output(TextureDecl d) { outputs.push_back(std::move(d)); return *this; }
    PassDeclaration& internal(TextureDecl d) { internals.push_back(std::move(d)); return *this; }
    PassDeclaration& param(ParamDecl d) { params.push_back(std::move(d)); return *this; }
};

// Shorthands for the common declarations.
inline ParamDecl floatParam(std::string name, float def, double lo, double hi, std::string doc = {}) {
    ParamDecl p; p.name = std::move(name); p.type = ParamType::Float; p.def = def; p.min = lo; p.max = hi; p.doc = std::move(doc);
    return p;
}
inline ParamDecl intParam(std::string name, int def, double lo, double hi, std::string doc = {}) {
    ParamDecl p; p.name = std::move(name); p.type = ParamType::Int; p.def = def; p.min = lo; p.max = hi; p.doc = std::move(doc);
    return p;
}
inline ParamDecl intChoiceParam(std::string name, int def, std::vector<int> allowed, std::string doc = {}) {
    ParamDecl p; p.name = std::move(name); p.type = ParamType::Int; p.def = def; p.intChoices = std::move(allowed); p.doc = std::move(doc);
    return p;
}
inline ParamDecl boolParam(std::string name, bool def, std::string doc = {}) {
    ParamDecl p; p.name = std::move(name); p.type = ParamType::Bool; p.def = def; p.doc = std::move(doc);
    return p;
}
inline ParamDecl enumParam(std::string name, std::string def, std::vector<std::string> choices, std::string doc = {}) {
    ParamDecl p; p.name = std::move(name); p.type = ParamType::Enum; p.def = std::move(def); p.choices = std::move(choices); p.doc = std::move(doc);
    return p;
}
inline ParamDecl colorParam(std::string name, Color3 def, std::string doc = {}) {
    ParamDecl p; p.name = std::move(name); p.type = ParamType::Color; p.def = def; p.doc = std::move(doc);
    return p;
}

}  // namespace kiln
