// kiln/module_loader.hpp — finds pass modules by name and loads them safely.
//
// A module named `bloom` is the file `libpass_bloom.so` in one of the module
// directories. Names must match [a-z0-9_]+ (no path, no "..", no suffix). Every load
// copies the file to a fresh private path first: dlopen caches by path, and a
// rebuilt library must never be overwritten while it is mapped.
//
// Loading is the one call the in-process guard (kiln/guard.hpp) cannot make safe: a
// crash in a library's static initialisers happens inside dlopen, with the dynamic
// loader's lock held. So a copy is first checked as a file (ELF headers, segments and
// dynamic section inside it, the entry symbol named), then opened in a child process,
// and only then in the host. Every later call into the module (create, declare,
// execute, destroy) runs under the guard; a module that faulted is marked, and its
// library is never unloaded (its destructors may fault too).
#pragma once

#include <filesystem>
#include <functional>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "kiln/guard.hpp"
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
    // The guard's watch for a call into this library: the watchdog interrupts only while
    // the library's own code runs.
    guard::Watch watch() const { return {true, code_}; }

    // Set when code of this library faulted: the message names the file, the fault and
    // the entry point. A faulted library stays mapped for the rest of the run.
    void markFaulted(std::string message);
    bool faulted() const { return !fault_.empty(); }
    const std::string& fault() const { return fault_; }
    // True the first time it is asked after a fault: whoever gets true prints it.
    bool takeFaultToReport() { return faulted() && !std::exchange(faultReported_, true); }

private:
    friend class ModuleLoader;
    LoadedModule() = default;
    std::string name_;
    std::filesystem::path source_, loadedCopy_;
    void* handle_ = nullptr;
    const KilnPassModule* desc_ = nullptr;
    std::string fault_;
    bool faultReported_ = false;
    guard::CodeRange code_;
};

// A pass object that keeps its library loaded for as long as it lives, and is
// destroyed by the library that created it (under the guard: a fault in destroy()
// marks the library, for the owner to report).
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

    // Creates a pass from a loaded module; null with `error` if the factory fails or
    // faults.
    static PassPtr create(const std::shared_ptr<LoadedModule>& module, std::string& error);

    const std::vector<std::filesystem::path>& dirs() const { return dirs_; }

    // The ELF check load() runs before dlopen: false (with `why`) for a file that is not
    // a complete 64-bit ELF shared library — garbage, one cut short, or one whose body
    // is not written yet (a dynamic section without the entry symbol's name).
    static bool checkFile(const std::filesystem::path& file, std::string& why);

private:
    // Why `name` was not found: where it looked, the nearest name, what is there.
    std::string notFound(const std::string& name) const;
    // A private copy of `source` under a name never used before in this process (not
    // only by this loader: a faulted library stays mapped): dlopen would hand back a
    // cached handle for a path it has seen, and the linker may rewrite the original.
    // Empty, with `error`, when it cannot be made.
    std::filesystem::path privateCopy(const std::filesystem::path& source, const std::string& name,
                                      std::string& error) const;

    std::vector<std::filesystem::path> dirs_;
    std::filesystem::path scratch_;  // private copies of loaded libraries
};

}  // namespace kiln
