// In-memory pass declarations standing in for the real modules, so the graph compiler
// is tested without loading any shared library (and without GL).
#pragma once

#include "graph/compiler.hpp"

#include <map>
#include <string>

namespace kiln::graph::test {

inline std::map<std::string, PassDeclaration> fakeModules() {
    std::map<std::string, PassDeclaration> m;

    m["gbuffer"]
        .output({"albedo", TextureKind::Color2D, Format::RGBA8, SizeRule::relative(), 1, ""})
        .output({"normal", TextureKind::Color2D, Format::RGBA16F, SizeRule::relative(), 1, ""})
        .output({"depth", TextureKind::Depth2D, Format::Depth32F, SizeRule::relative(), 1, ""})
        .param(boolParam("wireframe", false));

    m["shadow"]
        .output({"depth", TextureKind::Depth2D, Format::Depth32F, SizeRule::fromParam("size"), 1, ""})
        .param(intParam("size", 1024, 16, 8192))
        .param(floatParam("bias", 0.002f, 0.0, 0.1));

    m["voxelize"]
        .input({"shadow_map", TextureKind::Depth2D, true, Fallback::FarDepth, ""})
        .output({"radiance", TextureKind::Color3D, Format::RGBA16F, SizeRule::fromParam("resolution"), kFullMipChain, ""})
        .param(intChoiceParam("resolution", 64, {32, 64, 128}));

    m["cone_trace"]
        .input({"voxels", TextureKind::Color3D, true, Fallback::Black, ""})
        .input({"normal", TextureKind::Color2D, true, Fallback::FlatNormal, ""})
        .input({"depth", TextureKind::Depth2D, true, Fallback::FarDepth, ""})
        .output({"gi", TextureKind::Color2D, Format::RGBA16F, SizeRule::relative(0.5f), 1, ""})
        .param(intChoiceParam("cones", 6, {1, 5, 6, 9, 16}));

    m["bloom"]
        .input({"color", TextureKind::Color2D, true, Fallback::Black, ""})
        .output({"color", TextureKind::Color2D, Format::RGBA16F, SizeRule::relative(0.5f), 1, ""})
        .internal({"ping", TextureKind::Color2D, Format::RGBA16F, SizeRule::relative(0.5f), 1, ""})
        .param(floatParam("threshold", 1.0f, 0.0, 100.0))
        .param(intParam("radius", 4, 1, 16));

    m["composite"]
        .input({"albedo", TextureKind::Color2D, true, Fallback::Black, ""})
        .input({"normal", TextureKind::Color2D, true, Fallback::FlatNormal, ""})
        .input({"depth", TextureKind::Depth2D, true, Fallback::FarDepth, ""})
        .input({"shadow_map", TextureKind::Depth2D, false, Fallback::FarDepth, ""})
        .input({"bloom", TextureKind::Color2D, false, Fallback::Black, ""})
        .input({"gi", TextureKind::Color2D, false, Fallback::Black, ""})
        .output({"color", TextureKind::Color2D, Format::RGBA8, SizeRule::relative(), 1, ""})
        .param(floatParam("exposure", 1.0f, 0.0, 16.0))
        .param(enumParam("tonemap", "aces", {"aces", "reinhard", "none"}))
        .param(colorParam("tint", {1.0f, 1.0f, 1.0f}))
        .param(boolParam("pcf", true));

    // Outputs sized like an input: a half-size copy of a 3D volume (voxel_mip's shape).
    m["halve"]
        .input({"volume", TextureKind::Color3D, true, Fallback::Black, ""})
        .output({"half", TextureKind::Color3D, Format::RGBA16F, SizeRule::fromInput("volume", 0.5f), 1, ""})
        .output({"strip", TextureKind::Color3D, Format::RGBA16F, SizeRule::fromInput("volume", 0.5f, 12), 1, ""});
    m["input_sized_wrong"]
        .input({"volume", TextureKind::Color3D, true, Fallback::Black, ""})
        .output({"copy", TextureKind::Color3D, Format::RGBA16F, SizeRule::fromInput("volum"), 1, ""});

    // A module whose declaration is wrong: its output size names a missing parameter.
    m["broken_decl"]
        .output({"color", TextureKind::Color2D, Format::RGBA8, SizeRule::fromParam("sise"), 1, ""})
        .param(floatParam("size", 1.0f, 0.0, 2.0));
    // Same, but the size parameter is a float.
    m["float_size"]
        .output({"color", TextureKind::Color2D, Format::RGBA8, SizeRule::fromParam("size"), 1, ""})
        .param(floatParam("size", 1.0f, 0.0, 2.0));
    // A divided-size output whose divisor is a float, and a 3D one sized by the picture.
    m["float_divisor"]
        .output({"color", TextureKind::Color2D, Format::RGBA8, SizeRule::relativeOverParam("stride"), 1, ""})
        .param(floatParam("stride", 2.0f, 1.0, 4.0));
    // A divided-size output capped by a parameter that is not there.
    m["capped_by_nothing"]
        .output({"color", TextureKind::Color2D, Format::RGBA8, SizeRule::relativeOverParam("stride", 1.0f, "cpa"), 1, ""})
        .param(intParam("stride", 2, 1, 4))
        .param(intParam("cap", 64, 0, 512));
    m["divided_volume"]
        .output({"color", TextureKind::Color3D, Format::RGBA8, SizeRule::relativeOverParam("stride"), 1, ""})
        .param(intParam("stride", 2, 1, 4));
    // Outputs filled only for some values: one naming a value the enum does not have,
    // one naming a parameter that is not an enum, and a tiled strip with 0 tiles.
    m["produced_when_wrong"]
        .output({"color", TextureKind::Color2D, Format::RGBA8, SizeRule::relative(), 1, "", 0.0f, 0.0f,
                 ProducedWhen{"mode", {"fast", "slwo"}}})
        .output({"other", TextureKind::Color2D, Format::RGBA8, SizeRule::relative(), 1, "", 0.0f, 0.0f,
                 ProducedWhen{"scale", {"1"}}})
        .output({"strip", TextureKind::Color3D, Format::RGBA8, SizeRule::fromInput("volume", 1.0f, 0), 1, ""})
        .input({"volume", TextureKind::Color3D, false, Fallback::Black, ""})
        .param(enumParam("mode", "fast", {"fast", "slow"}))
        .param(floatParam("scale", 1.0f, 0.0, 2.0));
    return m;
}

// Options with a resolver over fakeModules(); "crashy" is listed as available but its
// resolver fails, like a .so that does not load.
inline CompileOptions fakeOptions(std::vector<std::string> requested = {}) {
    static const std::map<std::string, PassDeclaration> modules = fakeModules();
    CompileOptions o;
    o.resolve = [](const std::string& name) -> Result<PassDeclaration> {
        if (name == "crashy") return Result<PassDeclaration>::failure("dlopen failed: libpass_crashy.so: undefined symbol foo");
        auto it = modules.find(name);
        if (it == modules.end()) return Result<PassDeclaration>::failure("no such module");
        return it->second;
    };
    for (const auto& [name, decl] : modules) o.availableModules.push_back(name);
    o.availableModules.push_back("crashy");
    o.requested = std::move(requested);
    return o;
}

// The reference pipeline of the tests.
inline const char* kBasicPipeline = R"({
  "note": "gbuffer + shadow + composite; bloom reads the gbuffer but nothing reads bloom",
  "output": "composite.color",
  "passes": [
    { "id": "gbuffer", "module": "gbuffer" },
    { "id": "shadow", "module": "shadow", "params": { "size": 2048 } },
    { "id": "bloom", "module": "bloom", "inputs": { "color": "gbuffer.albedo" } },
    { "id": "composite", "module": "composite",
      "inputs": { "albedo": "gbuffer.albedo", "normal": "gbuffer.normal", "depth": "gbuffer.depth",
                  "shadow_map": "shadow.depth" },
      "params": { "exposure": 1.5, "tonemap": "reinhard", "tint": [1, 0.9, 0.8] } }
  ]
})";

}  // namespace kiln::graph::test
