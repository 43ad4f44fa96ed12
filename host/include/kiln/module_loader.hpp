// kiln/module_loader.hpp — finds pass modules by name and loads them safely.
//
// A module named `bloom` is the file `libpass_bloom.so` in one of the module
// directories. Names must match [a-z0-9_]+ (no path, no "..", no suffix). Every load
// copies the file to a fresh private path first: dlopen caches by path, and a
// rebuilt library must never be overwritten while it is mapped.
#pragma once

#include <filesystem>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "kiln/pass.hpp"

namespace kiln {

class LoadedModule {
public:
    ~LoadedModule();
    LoadedModule(const LoadedModule&) = delete;
    LoadedModule& operator=(const LoadedModule&) = delete;

    const std::string& name() const { return name_; }
    const std::filesystem::path& sourcePath() const { return source_; }
    const KilnPassModule& descriptor() const { return *desc_; }

private:
    friend class ModuleLoader;
    LoadedModule() = default;
    std::string name_;
    std::filesystem::path source_, loadedCopy_;
    void* handle_ = nullptr;
    const KilnPassModule* desc_ = nullptr;
};

// A pass object that keeps its library loaded for as long as it lives, and is
// destroyed by the library that created it.
using PassPtr = std::unique_ptr<Pass, std::function<void(Pass*)>>;

class ModuleLoader {
public:
    explicit ModuleLoader(std::vector<std::filesystem::path> dirs);
    ~ModuleLoader();

    static std::string fileNameFor(const std::string& name) { return "libpass_" + name + ".so"; }

    // Module names present in the directories, sorted.
    std::vector<std::string> available() const;
    // Path a module would be loaded from, or empty.
    std::filesystem::path locate(const std::string& name) const;

    // Loads (a fresh copy of) the module. On failure returns null and sets `error`
    // to one line naming the file and what is wrong.
    std::shared_ptr<LoadedModule> load(const std::string& name, std::string& error);

    // Creates a pass from a loaded module; null with `error` if the factory fails.
    static PassPtr create(const std::shared_ptr<LoadedModule>& module, std::string& error);

    const std::vector<std::filesystem::path>& dirs() const { return dirs_; }

    // The ELF check load() runs before dlopen: false (with `why`) for a file that is not
    // a complete 64-bit ELF shared library — garbage, or one still being written.
    static bool checkFile(const std::filesystem::path& file, std::string& why);

private:
    std::vector<std::filesystem::path> dirs_;
    std::filesystem::path scratch_;  // private copies of loaded libraries
    unsigned serial_ = 0;
};

}  // namespace kiln
