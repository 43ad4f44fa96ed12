// "extends": a pipeline written as the changes to another. See graph/pipeline.hpp.
#include <algorithm>
#include <filesystem>
#include <set>

#include "graph/pipeline.hpp"
#include "kiln/names.hpp"

namespace kiln::graph {

namespace {

namespace fs = std::filesystem;

// A chain longer than this is a mistake, not a design.
constexpr int kMaxExtendsDepth = 16;

Diagnostic errorAt(const std::string& file, const std::string& path, std::string message) {
    Diagnostic d;
    d.file = file;
    d.path = path;
    d.message = std::move(message);
    return d;
}

std::string passPath(size_t i) { return "passes[" + std::to_string(i) + "]"; }

template <typename T>
void setOrAdd(std::vector<std::pair<std::string, T>>& list, const std::string& key, const T& value) {
    auto it = std::find_if(list.begin(), list.end(), [&](const auto& kv) { return kv.first == key; });
    if (it != list.end()) it->second = value;
    else list.emplace_back(key, value);
}

std::vector<std::string> idsOf(const PipelineDesc& desc) {
    std::vector<std::string> ids;
    for (const PassDesc& p : desc.passes) ids.push_back(p.id);
    return ids;
}

// Lays `child`'s entries over `base` (already resolved); errors are the child's.
void merge(const PipelineDesc& child, PipelineDesc& base, std::vector<Diagnostic>& errors) {
    const std::string& file = child.fileName;
    for (size_t i = 0; i < base.passes.size(); ++i)  // what the base keeps is reported where it wrote it
        if (base.passes[i].origin.file.empty()) base.passes[i].origin = {base.fileName, int(i)};
    for (size_t i = 0; i < child.passes.size(); ++i) {
        const PassDesc& entry = child.passes[i];
        const std::string path = passPath(i);
        const int found = base.find(entry.id);
        auto anchorOf = [&](const std::string& anchor, const char* key) -> int {
            if (anchor.empty()) return -1;
            const int at = base.find(anchor);
            if (at < 0)
                errors.push_back(errorAt(file, path + "." + key, "no pass \"" + anchor + "\" in what " + file + " extends" +
                                                                     suggestion(anchor, idsOf(base), "passes")));
            return at;
        };
        const int before = anchorOf(entry.placeBefore, "before"), after = anchorOf(entry.placeAfter, "after");
        if ((!entry.placeBefore.empty() && before < 0) || (!entry.placeAfter.empty() && after < 0)) continue;
        if (entry.remove) {
            if (found < 0) {
                errors.push_back(errorAt(file, path + ".remove", "no pass \"" + entry.id + "\" to remove in what " + file +
                                                                      " extends" + suggestion(entry.id, idsOf(base), "passes")));
                continue;
            }
            base.passes.erase(base.passes.begin() + found);
            continue;
        }
        PassDesc pass;
        if (found >= 0 && entry.module.empty()) {  // re-parameterised: the entry's keys over the base's
            pass = base.passes[size_t(found)];
            // null takes the base's value away: a parameter back to its default, an input unbound.
            for (const auto& [name, value] : entry.params)
                if (value.type == ParamLiteral::Type::Null) std::erase_if(pass.params, [&](const auto& kv) { return kv.first == name; });
                else setOrAdd(pass.params, name, value);
            for (const auto& [slot, binding] : entry.inputs)
                if (binding.empty()) std::erase_if(pass.inputs, [&](const auto& kv) { return kv.first == slot; });
                else setOrAdd(pass.inputs, slot, binding);
            if (entry.enabledGiven) pass.enabled = entry.enabled;
            if (!entry.note.empty()) pass.note = entry.note;
        } else if (found < 0 && entry.module.empty()) {
            errors.push_back(errorAt(file, path, "no pass \"" + entry.id + "\" in what " + file + " extends" +
                                                     suggestion(entry.id, idsOf(base), "passes") +
                                                     "; a pass it adds names its \"module\""));
            continue;
        } else {
            pass = entry;  // added, or replaced whole
        }
        pass.origin = {file, int(i)};
        pass.placeBefore.clear(), pass.placeAfter.clear();
        const bool moves = before >= 0 || after >= 0;
        if (found >= 0 && !moves) {
            base.passes[size_t(found)] = std::move(pass);
            continue;
        }
        if (found >= 0) base.passes.erase(base.passes.begin() + found);
        // The anchors' places after the erase.
        const int anchor = base.find(before >= 0 ? entry.placeBefore : entry.placeAfter);
        const size_t at = !moves ? base.passes.size() : size_t(anchor + (before >= 0 ? 0 : 1));
        base.passes.insert(base.passes.begin() + std::ptrdiff_t(at), std::move(pass));
    }
    base.fileName = child.fileName;
    base.schema = child.schema;
    base.note = child.note;
    if (!child.output.empty()) base.output = child.output;
}

// Beside the file, then in the search directories; the first that exists (or, when none
// does, the one beside the file, so the error names where it was looked for first).
std::string locateBase(const PipelineDesc& desc, const std::vector<std::string>& searchDirs) {
    const fs::path extends(desc.extends);
    const fs::path beside = (fs::path(desc.fileName).parent_path() / extends).lexically_normal();
    if (extends.is_absolute()) return extends.lexically_normal().string();
    std::error_code ec;
    if (fs::exists(beside, ec)) return beside.string();
    for (const std::string& dir : searchDirs)
        if (const fs::path there = (fs::path(dir) / extends).lexically_normal(); fs::exists(there, ec)) return there.string();
    return beside.string();
}

Result<PipelineDesc> resolve(PipelineDesc desc, const PipelineReader& read, std::vector<std::string>& chain,
                             const std::vector<std::string>& searchDirs) {
    if (desc.extends.empty()) {
        // The keys that only say how to change a base mean nothing here.
        std::vector<Diagnostic> errors;
        for (size_t i = 0; i < desc.passes.size(); ++i) {
            const PassDesc& p = desc.passes[i];
            for (const auto& [used, key] : {std::pair{p.remove, "remove"}, std::pair{!p.placeBefore.empty(), "before"},
                                            std::pair{!p.placeAfter.empty(), "after"}})
                if (used)
                    errors.push_back(errorAt(desc.fileName, passPath(i) + "." + key,
                                             std::string("\"") + key + "\" changes the pipeline this one extends; this "
                                             "file has no \"extends\""));
            for (const auto& [slot, binding] : p.inputs)
                if (binding.empty())
                    errors.push_back(errorAt(desc.fileName, passPath(i) + ".inputs." + slot,
                                             "null unbinds an input of the pipeline this one extends; this file has no "
                                             "\"extends\" (leave the input out)"));
        }
        if (!errors.empty()) return Result<PipelineDesc>(std::move(errors));
        return desc;
    }
    const std::string baseFile = locateBase(desc, searchDirs);
    if (std::find(chain.begin(), chain.end(), baseFile) != chain.end())
        return Result<PipelineDesc>(errorAt(desc.fileName, "extends", "\"" + desc.extends + "\" extends this file again (a cycle)"));
    if (int(chain.size()) > kMaxExtendsDepth)
        return Result<PipelineDesc>(errorAt(desc.fileName, "extends", "more than " + std::to_string(kMaxExtendsDepth) + " files extend one another"));
    std::string text, why;
    if (!read(baseFile, text, why)) {
        std::string also;
        for (const std::string& dir : searchDirs) also += (also.empty() ? " (nor in " : ", ") + dir;
        return Result<PipelineDesc>(
            errorAt(desc.fileName, "extends", baseFile + ": " + why + (also.empty() ? "" : also + ")")));
    }
    chain.push_back(baseFile);
    Result<PipelineDesc> base = parsePipeline(text, baseFile);
    if (!base) return base;
    Result<PipelineDesc> resolved = resolve(std::move(*base), read, chain, searchDirs);
    if (!resolved) return resolved;
    std::vector<Diagnostic> errors;
    merge(desc, *resolved, errors);
    if (!errors.empty()) return Result<PipelineDesc>(std::move(errors));
    return resolved;
}

}  // namespace

bool readPipelineFile(const std::string& file, std::string& text, std::string& why) {
    return json_text::readBoundedFile(file, kMaxPipelineFileBytes, "pipeline file", text, why);
}

Result<PipelineDesc> resolveExtends(PipelineDesc desc, const PipelineReader& read, std::vector<std::string>* chain,
                                    const std::vector<std::string>& searchDirs) {
    std::vector<std::string> files{fs::path(desc.fileName).lexically_normal().string()};
    Result<PipelineDesc> resolved = resolve(std::move(desc), read, files, searchDirs);
    if (chain) *chain = std::move(files);
    return resolved;
}

}  // namespace kiln::graph
