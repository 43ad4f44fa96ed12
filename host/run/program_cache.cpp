#include "run/program_cache.hpp"

#include <algorithm>
#include <set>

#include "kiln/log.hpp"

namespace kiln::run {

namespace {

std::string keyOf(const ProgramDesc& desc) {
    std::string key;
    for (auto& s : desc.stages) key += s + ";";
    for (auto& [k, v] : desc.defines) key += k + "=" + v + ";";
    return key;
}

// Logged once per build (a rebuild after an edit says it again, or stops saying it).
std::vector<std::string> portabilityOf(const ProgramBuild& build) {
    std::vector<std::string> out;
    for (const ShaderError& issue : build.portability) {
        out.push_back(issue.toString());
        log::warn(out.back());
    }
    return out;
}

std::string errorOf(const ProgramBuild& build) {
    std::string e = build.errorText();
    if (!e.empty() && e.back() == '\n') e.pop_back();
    return e;
}

}  // namespace

GLuint ProgramCache::get(const ShaderLibrary& shaders, const ProgramDesc& desc, std::string& error) {
    const std::string key = keyOf(desc);
    auto it = entries_.find(key);
    if (it == entries_.end()) {
        if (entries_.size() >= kMaxVariants) evictLeastRecentlyUsed();
        ProgramBuild build = buildProgram(shaders, desc);
        Entry entry;
        entry.desc = desc;
        entry.dependencies = build.dependencies;
        ++generation_;
        if (build.ok()) {
            entry.portability = portabilityOf(build);
            entry.program = std::move(build.program);
        } else {
            entry.error = errorOf(build);
            log::error(entry.error);
        }
        it = entries_.emplace(key, std::move(entry)).first;
    }
    it->second.lastUse = ++clock_;
    if (!it->second.program) {
        error = it->second.error;
        return 0;
    }
    return it->second.program.id();
}

void ProgramCache::evictLeastRecentlyUsed() {
    auto oldest = std::min_element(entries_.begin(), entries_.end(),
                                   [](auto& a, auto& b) { return a.second.lastUse < b.second.lastUse; });
    if (oldest != entries_.end()) entries_.erase(oldest);
}

int ProgramCache::reload(const ShaderLibrary& shaders, const std::vector<std::filesystem::path>& changed) {
    int rebuilt = 0;
    // Variants of one shader (the same files, other defines) fail alike: each error once.
    std::set<std::string> logged;
    for (auto& [key, entry] : entries_) {
        const bool affected = std::any_of(entry.dependencies.begin(), entry.dependencies.end(), [&](auto& dep) {
            return std::find(changed.begin(), changed.end(), dep) != changed.end();
        });
        if (!affected) continue;
        // Built aside; swapped in only if it compiles and links.
        ProgramBuild build = buildProgram(shaders, entry.desc);
        if (!build.dependencies.empty()) entry.dependencies = build.dependencies;
        if (build.ok()) {
            entry.portability = portabilityOf(build);
            entry.program = std::move(build.program);
            entry.error.clear();
            ++generation_;
            ++rebuilt;
        } else {
            entry.error = errorOf(build);
            if (logged.insert(entry.error).second) log::error(entry.error);
        }
    }
    return rebuilt;
}

std::vector<std::string> ProgramCache::standingErrors() const {
    std::vector<std::string> errors;
    for (auto& [key, entry] : entries_)
        if (!entry.error.empty() && entry.program && std::find(errors.begin(), errors.end(), entry.error) == errors.end())
            errors.push_back(entry.error);
    return errors;
}

std::vector<std::string> ProgramCache::portabilityWarnings() const {
    std::vector<std::string> warnings;
    for (auto& [key, entry] : entries_)
        if (entry.program) warnings.insert(warnings.end(), entry.portability.begin(), entry.portability.end());
    return warnings;
}

}  // namespace kiln::run
