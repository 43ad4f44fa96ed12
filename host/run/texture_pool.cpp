#include "run/texture_pool.hpp"

#include <algorithm>

#include "kiln/image_io.hpp"

namespace fs = std::filesystem;

namespace kiln::run {

GLenum glFormat(Format f) {
    switch (f) {
        case Format::RGBA8: return GL_RGBA8;
        case Format::RGBA16F: return GL_RGBA16F;
        case Format::RGBA32F: return GL_RGBA32F;
        case Format::RG16F: return GL_RG16F;
        case Format::R16F: return GL_R16F;
        case Format::R32F: return GL_R32F;
        case Format::R11G11B10F: return GL_R11F_G11F_B10F;
        case Format::R32UI: return GL_R32UI;
        case Format::Depth32F: return GL_DEPTH_COMPONENT32F;
        case Format::Depth24: return GL_DEPTH_COMPONENT24;
    }
    return GL_RGBA8;
}

bool isFloatFormat(GLenum f) { return f != GL_RGBA8 && f != GL_R32UI; }

size_t bytesPerTexel(Format f) {
    switch (f) {
        case Format::RGBA32F: return 16;
        case Format::RGBA16F: return 8;
        case Format::R16F: return 2;
        default: return 4;
    }
}

TextureLimits TextureLimits::query(uint64_t budgetBytes) {
    TextureLimits l;
    glGetIntegerv(GL_MAX_TEXTURE_SIZE, &l.max2D);
    glGetIntegerv(GL_MAX_3D_TEXTURE_SIZE, &l.max3D);
    l.budgetBytes = budgetBytes;
    return l;
}

namespace {

uint64_t bytesOf(const TextureDecl& d, graph::Extent e) {
    const bool is3D = d.kind == TextureKind::Color3D;
    const int levels = d.mips == kFullMipChain ? gl::Texture::fullMipCount(e.w, e.h, is3D ? e.d : 1) : std::max(1, d.mips);
    uint64_t total = 0;
    for (int l = 0; l < levels; ++l)
        total += uint64_t(std::max(1, e.w >> l)) * uint64_t(std::max(1, e.h >> l)) *
                 uint64_t(is3D ? std::max(1, e.d >> l) : 1);
    return total * bytesPerTexel(d.format);
}

std::string mib(uint64_t bytes) { return std::to_string((bytes + (1u << 20) - 1) >> 20) + " MiB"; }

}  // namespace

std::string checkTextureLimits(const graph::Plan& plan, int outW, int outH, const TextureLimits& limits,
                               const graph::GridShape& grid) {
    std::string problems;
    uint64_t total = 0;
    for (size_t i = 0; i < plan.passes.size(); ++i) {
        const graph::PlannedPass& p = plan.passes[i];
        if (p.state == graph::PassState::Disabled) continue;
        auto check = [&](const TextureDecl& d) {
            const graph::Extent e = plan.extentOf(int(i), d.name, outW, outH, grid);
            const bool is3D = d.kind == TextureKind::Color3D;
            const int limit = is3D ? limits.max3D : limits.max2D;
            const std::string size = std::to_string(e.w) + "x" + std::to_string(e.h) + (is3D ? "x" + std::to_string(e.d) : "");
            if (std::max({e.w, e.h, is3D ? e.d : 0}) > limit)
                problems += plan.fileName + ": passes[" + std::to_string(i) + "] (" + p.id + "): texture \"" + d.name +
                            "\" would be " + size + ", beyond this GL's " + (is3D ? "GL_MAX_3D_TEXTURE_SIZE " : "GL_MAX_TEXTURE_SIZE ") +
                            std::to_string(limit) + "\n";
            total += bytesOf(d, e);
        };
        for (auto& d : p.decl.outputs) check(d);
        for (auto& d : p.decl.internals) check(d);
    }
    if (total > limits.budgetBytes)
        problems += plan.fileName + ": its textures would take " + mib(total) + " at " + std::to_string(outW) + "x" +
                    std::to_string(outH) + ", over the texture budget of " + mib(limits.budgetBytes) + "\n";
    return problems;
}

namespace {

void clearToDefault(const gl::Texture& t) {
    for (int level = 0; level < t.levels(); ++level) {
        const GLenum f = t.internalFormat();
        if (gl::isDepthFormat(f)) {
            const float one = 1.0f;
            glClearTexImage(t.id(), level, GL_DEPTH_COMPONENT, GL_FLOAT, &one);
        } else if (gl::isIntegerFormat(f)) {
            glClearTexImage(t.id(), level, GL_RED_INTEGER, GL_UNSIGNED_INT, nullptr);
        } else {
            glClearTexImage(t.id(), level, GL_RGBA, GL_FLOAT, nullptr);
        }
    }
}

}  // namespace

bool ensureTexture(PassTextures& textures, const TextureDecl& d, graph::Extent e, bool internal,
                   const std::string& label, uint64_t newVersion) {
    const GLenum target = d.kind == TextureKind::Color3D ? GL_TEXTURE_3D : GL_TEXTURE_2D;
    const GLenum format = glFormat(d.format);
    if (target != GL_TEXTURE_3D) e.d = 1;
    const int levels = d.mips == kFullMipChain ? gl::Texture::fullMipCount(e.w, e.h, e.d) : std::max(1, d.mips);
    auto it = textures.find(d.name);
    if (it != textures.end()) {
        const gl::Texture& t = it->second.texture;
        if (t.target() == target && t.internalFormat() == format && t.width() == e.w && t.height() == e.h &&
            t.depth() == e.d && t.levels() == levels && it->second.internal == internal) {
            it->second.decl = d;
            return false;
        }
    }
    PooledTexture p;
    p.decl = d;
    p.internal = internal;
    p.texture = gl::Texture::create(target, format, e.w, e.h, e.d, levels, label);
    // Fresh textures start defined, so a pass that reports nothing to do on its first
    // run leaves zeros behind, not garbage.
    clearToDefault(p.texture);
    p.ref = {p.texture.id(), target, format, e.w, e.h, e.d, levels, true};
    p.version = newVersion;
    textures[d.name] = std::move(p);
    return true;
}

void FallbackTextures::create() {
    auto make2d = [&](int slot, GLenum fmt, const char* name, const float* rgba) {
        textures_[slot] = gl::Texture::create(GL_TEXTURE_2D, fmt, 1, 1, 1, 1, name);
        glClearTexImage(textures_[slot].id(), 0, fmt == GL_DEPTH_COMPONENT32F ? GL_DEPTH_COMPONENT : GL_RGBA, GL_FLOAT,
                        rgba);
    };
    const float black[4] = {0, 0, 0, 0}, white[4] = {1, 1, 1, 1}, flat[4] = {0, 0, 1, 0}, far[1] = {1.0f};
    make2d(kBlack, GL_RGBA16F, "fallback.black", black);
    make2d(kWhite, GL_RGBA16F, "fallback.white", white);
    make2d(kFlatNormal, GL_RGBA16F, "fallback.flat_normal", flat);
    make2d(kFarDepth, GL_DEPTH_COMPONENT32F, "fallback.far_depth", far);
    textures_[kBlack3D] = gl::Texture::create(GL_TEXTURE_3D, GL_RGBA16F, 1, 1, 1, 1, "fallback.black3d");
    glClearTexImage(textures_[kBlack3D].id(), 0, GL_RGBA, GL_FLOAT, black);
    for (int i = 0; i < kCount; ++i)
        refs_[i] = {textures_[i].id(), textures_[i].target(), textures_[i].internalFormat(), 1, 1, 1, 1, false};
}

const TextureRef& FallbackTextures::get(TextureKind kind, Fallback fb) const {
    if (kind == TextureKind::Color3D) return refs_[kBlack3D];
    if (kind == TextureKind::Depth2D) return refs_[kFarDepth];
    switch (fb) {
        case Fallback::White: return refs_[kWhite];
        case Fallback::FlatNormal: return refs_[kFlatNormal];
        case Fallback::FarDepth: return refs_[kFarDepth];
        case Fallback::Black: break;
    }
    return refs_[kBlack];
}

bool writeTextureImage(const FloatImage& image, GLenum internalFormat, const std::string& base, bool& withExr,
                       std::string& error) {
    withExr = isFloatFormat(internalFormat);
    return writePng(base + ".png", image, 4, error) && (!withExr || writeExr(base + ".exr", image, error));
}

bool dumpTextures(const std::vector<NamedTexture>& textures, const fs::path& dir, std::string& error) {
    std::error_code ec;
    fs::create_directories(dir, ec);
    if (ec) {
        error = dir.string() + ": cannot create directory: " + ec.message();
        return false;
    }
    for (auto& t : textures) {
        const TextureRef& r = t.ref;
        const int layer = r.target == GL_TEXTURE_3D ? r.depth / 2 : -1;
        FloatImage img = readTexture(r.id, r.target, r.format, r.width, r.height, 0, layer);
        bool withExr = false;
        if (!writeTextureImage(img, r.format, (dir / (t.pass + "." + t.name)).string(), withExr, error)) return false;
    }
    return true;
}

}  // namespace kiln::run
