// The non-inline half of kiln/declare.hpp: names of kinds, formats, fallbacks and
// parameter types. One table per enum, so a new format is one line.
#include "kiln/declare.hpp"

#include <algorithm>
#include <cctype>
#include <iterator>

namespace kiln {
namespace {

struct FormatInfo {
    Format format;
    const char* name;
    bool depth;
};

constexpr FormatInfo kFormats[] = {
    {Format::RGBA8, "rgba8", false},
    {Format::RGBA16F, "rgba16f", false},
    {Format::RGBA32F, "rgba32f", false},
    {Format::RG16F, "rg16f", false},
    {Format::R16F, "r16f", false},
    {Format::R32F, "r32f", false},
    {Format::R11G11B10F, "r11g11b10f", false},
    {Format::R32UI, "r32ui", false},
    {Format::Depth32F, "depth32f", true},
    {Format::Depth24, "depth24", true},
};

const FormatInfo* info(Format f) {
    for (const FormatInfo& i : kFormats)
        if (i.format == f) return &i;
    return nullptr;
}

}  // namespace

const char* toString(TextureKind k) {
    switch (k) {
        case TextureKind::Color2D: return "color 2D";
        case TextureKind::Depth2D: return "depth 2D";
        case TextureKind::Color3D: return "color 3D";
    }
    return "?";
}

const char* toString(Format f) {
    const FormatInfo* i = info(f);
    return i ? i->name : "?";
}

bool isDepthFormat(Format f) {
    const FormatInfo* i = info(f);
    return i && i->depth;
}

bool parseFormat(const std::string& name, Format& out) {
    std::string lower(name);
    std::transform(lower.begin(), lower.end(), lower.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    for (const FormatInfo& i : kFormats) {
        if (lower == i.name) {
            out = i.format;
            return true;
        }
    }
    return false;
}

const char* toString(Fallback f) {
    switch (f) {
        case Fallback::Black: return "black";
        case Fallback::White: return "white";
        case Fallback::FlatNormal: return "flat_normal";
        case Fallback::FarDepth: return "far_depth";
    }
    return "?";
}

const char* toString(ParamType t) {
    switch (t) {
        case ParamType::Bool: return "bool";
        case ParamType::Int: return "int";
        case ParamType::Float: return "float";
        case ParamType::Enum: return "enum";
        case ParamType::Color: return "color";
    }
    return "?";
}

}  // namespace kiln
