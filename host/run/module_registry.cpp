#include "run/module_registry.hpp"

#include <exception>

namespace kiln::run {

graph::Result<ModuleRegistry::Module> ModuleRegistry::probe(const std::string& name) {
    std::string error;
    auto library = loader_.load(name, error);
    if (!library) return graph::Result<Module>::failure(error);
    PassPtr object = ModuleLoader::create(library, error);
    if (!object) return graph::Result<Module>::failure(error);
    try {
        return Module{library, object->declare()};
    } catch (const std::exception& e) {
        return graph::Result<Module>::failure(library->sourcePath().string() + ": declare() threw: " + e.what());
    }
}

graph::Result<PassDeclaration> ModuleRegistry::declaration(const std::string& name) {
    if (const Module* m = find(name)) return m->decl;
    auto probed = probe(name);
    if (!probed) return probed.errors();
    modules_[name] = *probed;
    return probed->decl;
}

const ModuleRegistry::Module* ModuleRegistry::find(const std::string& name) const {
    auto it = modules_.find(name);
    return it == modules_.end() ? nullptr : &it->second;
}

}  // namespace kiln::run
