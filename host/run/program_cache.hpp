// run/program_cache.hpp — one pass's compiled programs, keyed by stages + defines.
//
// A program is built on first use and rebuilt when a file of its include closure is
// edited; a failed rebuild keeps the last good program, and its error stands until the
// file is fixed. The cache is bounded (kMaxVariants, least recently used goes): a
// slider over a parameter that a pass bakes into a define would otherwise leave one
// program per value behind.
#pragma once

#include <cstdint>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "kiln/shader.hpp"

namespace kiln::run {

class ProgramCache {
public:
    static constexpr size_t kMaxVariants = 16;

    // The program for `desc` (built now if new), or 0 when it has never compiled;
    // then `error` holds the mapped compiler output.
    GLuint get(const ShaderLibrary&, const ProgramDesc& desc, std::string& error);
    // Rebuilds every program that read one of `changed` (absolute paths). Returns how
    // many were rebuilt successfully.
    int reload(const ShaderLibrary&, const std::vector<std::filesystem::path>& changed);
    // Bumped whenever a program is (re)built, so the pass runs again.
    uint64_t generation() const { return generation_; }
    // Errors of edits that broke a program whose last good version still runs.
    std::vector<std::string> standingErrors() const;
    // Of the programs in use: what each uses beyond OpenGL 4.5's guaranteed minimums
    // (ProgramBuild::portability), one line each.
    std::vector<std::string> portabilityWarnings() const;
    size_t size() const { return entries_.size(); }

private:
    struct Entry {
        ProgramDesc desc;           // as built (defines included), to rebuild on a shader edit
        gl::ProgramHandle program;  // the last good one
        std::string error;
        std::vector<std::string> portability;  // of `program`
        std::vector<std::filesystem::path> dependencies;
        uint64_t lastUse = 0;
    };
    void evictLeastRecentlyUsed();

    std::map<std::string, Entry> entries_;
    uint64_t generation_ = 0, clock_ = 0;
};

}  // namespace kiln::run
