// run/texture_pool.hpp — the textures the host owns for the passes: allocation by
// declaration and extent (kept when the shape is unchanged, so a recompile or a resize
// keeps contents), the fallback textures unbound optional inputs read, the mapping
// from declared formats to GL, and writing them all to disk (--dump).
#pragma once

#include <cstdint>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "graph/plan.hpp"
#include "kiln/float_image.hpp"
#include "kiln/gl.hpp"
#include "kiln/pass.hpp"

namespace kiln::run {

GLenum glFormat(Format);
bool isFloatFormat(GLenum internalFormat);
size_t bytesPerTexel(Format);

// What the host refuses to allocate: a side beyond the GL limits, or a plan whose
// textures together exceed the budget (a pipeline asking for 4096³ voxels gets a named
// error, not an out-of-memory kill).
struct TextureLimits {
    int max2D = 16384, max3D = 2048;     // GL_MAX_TEXTURE_SIZE, GL_MAX_3D_TEXTURE_SIZE
    uint64_t budgetBytes = 8ull << 30;   // all textures of a plan together
    static TextureLimits query(uint64_t budgetBytes);
};

// Checks every texture of every pass that is not disabled at an output size of
// outW×outH (voxel grids shaped by `grid`); "" when all fit, else one line per problem
// naming the pass, the texture, its size and the limit.
std::string checkTextureLimits(const graph::Plan&, int outW, int outH, const TextureLimits&,
                               const graph::GridShape& grid = {});

struct PooledTexture {
    TextureDecl decl;
    gl::Texture texture;
    TextureRef ref;
    uint64_t version = 0;  // changes whenever its producer writes it (or it is new)
    bool internal = false;
};
// One pass's outputs and internal textures, by declared name.
using PassTextures = std::map<std::string, PooledTexture, std::less<>>;

// Makes `textures[decl.name]` a texture of `decl`'s format, kind and mip count at
// `extent`. One of the same shape is kept with its contents; otherwise a new one is
// created, cleared (colour 0, depth 1), labelled `label`, and given version
// `newVersion`. Returns true when it created one.
bool ensureTexture(PassTextures& textures, const TextureDecl& decl, graph::Extent extent, bool internal,
                   const std::string& label, uint64_t newVersion);

// What an unbound optional input reads: 1×1 black / white / flat normal / far depth
// (2D) and a black 1³ volume (3D).
class FallbackTextures {
public:
    void create();
    const TextureRef& get(TextureKind, Fallback) const;

private:
    enum { kBlack, kWhite, kFlatNormal, kFarDepth, kBlack3D, kCount };
    gl::Texture textures_[kCount];
    TextureRef refs_[kCount];
};

struct NamedTexture {
    std::string pass, name;
    bool internal;
    TextureRef ref;
    float depthNear = 0.0f, depthFar = 0.0f;  // TextureDecl's: how to linearise a depth texture
    int tiles = 1;                             // blocks side by side along x (SizeRule::tiles)
    bool read = true;    // false: an output nothing reads this frame (PassContext::isRead)
    bool stale = false;  // unread, and declared onlyWhenRead: not written this frame
    // Declared with the host camera's planes (kCameraNear, kCameraFar): the camera's
    // depth. depthFar is then the camera's far plane of the last frame, which reaches
    // past kCameraFar in a scene larger than the box.
    bool cameraDepth = false;
};

// Writes `image`, read back from a texture of `internalFormat`, as BASE.png (clamped to
// [0,1]) and, for float and depth formats, BASE.exr with the raw values. True when the
// EXR was written too in `withExr`.
bool writeTextureImage(const FloatImage& image, GLenum internalFormat, const std::string& base, bool& withExr,
                       std::string& error);

// Writes each texture into `dir` as PASS.NAME.png (clamped to [0,1]) and, for float
// and depth formats, PASS.NAME.exr with the raw values. 3D textures: the middle slice
// of level 0.
bool dumpTextures(const std::vector<NamedTexture>&, const std::filesystem::path& dir, std::string& error);

}  // namespace kiln::run
