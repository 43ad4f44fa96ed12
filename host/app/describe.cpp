#include "app/describe.hpp"

#include <cstdio>

#include "app/context.hpp"
#include "command_line/command_line.hpp"
#include "graph/plan.hpp"
#include "kiln/log.hpp"
#include "kiln/names.hpp"
#include "run/module_registry.hpp"

namespace kiln::app {

namespace {

std::string number(double x) {
    char b[32];
    std::snprintf(b, sizeof b, "%g", x);
    return b;
}

std::string rangeText(const ParamDecl& p) {
    auto join = [](const auto& items, auto&& text) {
        std::string out;
        for (const auto& i : items) out += (out.empty() ? "" : ", ") + text(i);
        return out;
    };
    if (p.type == ParamType::Enum) return join(p.choices, [](const std::string& c) { return c; });
    if (!p.intChoices.empty()) return join(p.intChoices, [](int c) { return std::to_string(c); });
    if ((p.type == ParamType::Int || p.type == ParamType::Float) && p.min != p.max)
        return number(p.min) + " to " + number(p.max);
    if (p.type == ParamType::Color) return "linear RGB";
    return "";
}

std::string sizeText(const SizeRule& s) {
    const std::string scale = s.scale == 1.0f ? "" : number(s.scale) + " × ";
    const std::string tiles = s.tiles > 1 ? ", " + std::to_string(s.tiles) + " side by side" : "";
    switch (s.mode) {
        case SizeRule::Mode::RelativeToOutput: return scale + "the output";
        case SizeRule::Mode::Fixed:
            return std::to_string(s.width) + "×" + std::to_string(s.height) + (s.depth > 1 ? "×" + std::to_string(s.depth) : "");
        case SizeRule::Mode::FromParam: return scale + "`" + s.source + "` on a side" + tiles;
        case SizeRule::Mode::FromInput: return scale + "input `" + s.source + "`" + tiles;
        case SizeRule::Mode::RelativeOverParam:
            return scale + "the output ÷ `" + s.source + "`" + (s.capSource.empty() ? "" : " (capped by `" + s.capSource + "`)");
    }
    return "";
}

// Table cells: a '|' in a doc string would end the cell.
std::string cell(std::string text) {
    for (size_t at = text.find('|'); at != std::string::npos; at = text.find('|', at + 2)) text.replace(at, 1, "\\|");
    return text;
}

std::string readsText(uint32_t reads) {
    static const std::pair<uint32_t, const char*> kNames[] = {
        {kScenePlanes, "planes"},          {kSceneLightSurface, "light surface"}, {kSceneMeshes, "meshes"},
        {kSceneRoundCones, "round cones"}, {kSceneSpheres, "spheres"},          {kSceneGlowingSpheres, "glowing spheres"},
        {kSceneParticles, "particles"},    {kSceneLights, "lights"},            {kSceneCamera, "camera"},
        {kSceneTime, "time"}};
    std::string out;
    for (const auto& [bit, name] : kNames)
        if (reads & bit) out += (out.empty() ? "" : ", ") + std::string(name);
    return out.empty() ? "nothing" : out;
}

std::string describe(const std::string& name, const PassDeclaration& d) {
    std::string md = "## " + name + "\n\nReads from the scene: " + readsText(d.reads) + "." +
                     (d.timeDependent ? " Runs every frame (time-dependent)." : "") + "\n";
    if (!d.inputs.empty()) {
        md += "\n| input | kind | when unbound | doc |\n|---|---|---|---|\n";
        for (const InputDecl& i : d.inputs)
            md += "| `" + i.name + "` | " + toString(i.kind) + " | " +
                  (i.required ? std::string("required") : std::string(toString(i.fallback))) + " | " + cell(i.doc) + " |\n";
    }
    auto textures = [&](const char* what, const std::vector<TextureDecl>& list) {
        if (list.empty()) return;
        md += std::string("\n| ") + what + " | kind | format | size | mips | doc |\n|---|---|---|---|---|---|\n";
        for (const TextureDecl& t : list) {
            std::string doc = t.doc;
            if (!t.producedWhen.param.empty()) {
                doc += (doc.empty() ? "" : " ") + std::string("Filled when `") + t.producedWhen.param + "` is ";
                for (size_t k = 0; k < t.producedWhen.values.size(); ++k)
                    doc += (k ? " or " : "") + t.producedWhen.values[k];
                doc += ".";
            }
            if (t.onlyWhenRead) doc += (doc.empty() ? "" : " ") + std::string("Written only while something reads it.");
            md += "| `" + t.name + "` | " + toString(t.kind) + " | " + toString(t.format) + " | " + sizeText(t.size) +
                  " | " + (t.mips == kFullMipChain ? std::string("full chain") : std::to_string(t.mips)) + " | " + cell(doc) + " |\n";
        }
    };
    textures("output", d.outputs);
    textures("internal", d.internals);
    if (!d.params.empty()) {
        md += "\n| parameter | type | default | range | doc |\n|---|---|---|---|---|\n";
        for (const ParamDecl& p : d.params)
            md += "| `" + p.name + "` | " + toString(p.type) + " | " + cell(graph::formatParamValue(p.def)) + " | " + cell(rangeText(p)) +
                  " | " + cell(p.doc) + " |\n";
    }
    return md;
}

// The registry probes each module (loads it, asks one object for its declaration); a
// context is current while it does, as for a running pipeline.
struct Probe {
    std::unique_ptr<HeadlessContext> context;
    std::unique_ptr<run::ModuleRegistry> registry;
};

std::optional<Probe> startProbe(const Options& o) {
    std::string error;
    Probe p;
    p.context = HeadlessContext::create(false, error);
    if (!p.context) {
        log::error(error);
        return std::nullopt;
    }
    std::vector<std::filesystem::path> dirs;
    for (const std::string& dir : pathList(o.moduleDir)) dirs.emplace_back(dir);
    p.registry = std::make_unique<run::ModuleRegistry>(std::move(dirs));
    return p;
}

}  // namespace

int listModules(const Options& o) {
    auto probe = startProbe(o);
    if (!probe) return cli::kExitFailure;
    int failed = 0;
    for (const std::string& name : probe->registry->loader().available()) {
        auto decl = probe->registry->declaration(name);
        if (!decl) {
            log::error(decl.errorText());
            ++failed;
            continue;
        }
        std::string outputs;
        for (const TextureDecl& t : decl->outputs) outputs += (outputs.empty() ? "" : ", ") + t.name;
        std::printf("%-12s %zu inputs, %zu parameters; outputs %s  (%s)\n", name.c_str(), decl->inputs.size(),
                    decl->params.size(), outputs.empty() ? "none" : outputs.c_str(),
                    probe->registry->loader().locate(name).string().c_str());
    }
    return failed ? cli::kExitFailure : 0;
}

int describeModules(const Options& o, const std::string& module) {
    auto probe = startProbe(o);
    if (!probe) return cli::kExitFailure;
    const std::vector<std::string> available = probe->registry->loader().available();
    std::vector<std::string> names = module == "all" ? available : std::vector<std::string>{module};
    if (module != "all" && std::find(available.begin(), available.end(), module) == available.end()) {
        std::fprintf(stderr, "kiln: error: --describe %s: no module \"%s\" in %s%s (see kiln --list-modules)\n",
                     module.c_str(), module.c_str(), o.moduleDir.c_str(), suggestion(module, available, "modules").c_str());
        return cli::kExitUsage;
    }
    std::string md;
    if (module == "all")
        md = "# Pass modules\n\nWhat each shipped pass module declares: its inputs, outputs and parameters, as the "
             "graph compiler checks a pipeline against them. Generated by `kiln --describe all`.\n";
    for (const std::string& name : names) {
        auto decl = probe->registry->declaration(name);
        if (!decl) {
            log::error(decl.errorText());
            return cli::kExitFailure;
        }
        md += (md.empty() ? "" : "\n") + describe(name, *decl);
    }
    std::fputs(md.c_str(), stdout);
    return 0;
}

}  // namespace kiln::app
