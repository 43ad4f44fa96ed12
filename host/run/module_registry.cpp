#include "run/module_registry.hpp"

#include "kiln/guard.hpp"

namespace kiln::run {

graph::Result<ModuleRegistry::Module> ModuleRegistry::probe(const std::string& name) {
    std::string error;
    auto library = loader_.load(name, error);
    if (!library) return graph::Result<Module>::failure(error);
    PassPtr object = ModuleLoader::create(library, error);
    if (!object) return graph::Result<Module>::failure(error);
    PassDeclaration decl;
    if (auto fault = guard::guarded([&] { decl = object->declare(); }, library->watch())) {
        const std::string what = library->sourcePath().filename().string() + ": " + *fault + " in declare()";
        if (!guard::unwound(*fault)) library->markFaulted(what);
        return graph::Result<Module>::failure(library->sourcePath().string() + ": " + *fault + " in declare()");
    }
    object.reset();  // destroy() is tried here too: a module that faults in it is refused now
    if (library->takeFaultToReport())
        return graph::Result<Module>::failure(library->sourcePath().parent_path().string() + "/" + library->fault());
    return Module{library, std::move(decl)};
}

void ModuleRegistry::keepAsPrevious(const std::string& name, Module replaced) {
    if (replaced.library->faulted()) previous_.erase(name);
    else previous_[name] = std::move(replaced);
}

const ModuleRegistry::Module* ModuleRegistry::previous(const std::string& name) const {
    auto it = previous_.find(name);
    return it == previous_.end() ? nullptr : &it->second;
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
