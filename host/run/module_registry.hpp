// run/module_registry.hpp — the pass modules a running plan uses: each loaded once,
// with the declaration one probe object gave. The graph compiler asks it for
// declarations; a live module reload probes a fresh copy aside and registers it only
// once the pipeline has been validated against the new declaration. The build it
// replaced is kept (mapped, without objects) until the next reload: a new build that
// faults is rolled back to it.
#pragma once

#include <filesystem>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "graph/diagnostic.hpp"
#include "kiln/module_loader.hpp"

namespace kiln::run {

class ModuleRegistry {
public:
    struct Module {
        std::shared_ptr<LoadedModule> library;
        PassDeclaration decl;
    };

    explicit ModuleRegistry(std::vector<std::filesystem::path> dirs) : loader_(std::move(dirs)) {}

    // The registered module's declaration; loads and probes it on first use.
    graph::Result<PassDeclaration> declaration(const std::string& name);
    // Loads a fresh copy of `name` and asks one object for its declaration, without
    // touching what is registered.
    graph::Result<Module> probe(const std::string& name);

    const Module* find(const std::string& name) const;
    void set(const std::string& name, Module m) { modules_[name] = std::move(m); }
    void erase(const std::string& name) { modules_.erase(name); }
    // After a reload: the build it replaced, kept to roll back to (unless it faulted).
    void keepAsPrevious(const std::string& name, Module replaced);
    const Module* previous(const std::string& name) const;
    bool uses(const std::string& name) const { return modules_.count(name) > 0; }
    // Objects first, then libraries: a pass object's code lives in its library.
    void clear() {
        modules_.clear();
        previous_.clear();
    }

    ModuleLoader& loader() { return loader_; }
    const ModuleLoader& loader() const { return loader_; }

private:
    ModuleLoader loader_;
    std::map<std::string, Module> modules_, previous_;
};

}  // namespace kiln::run
