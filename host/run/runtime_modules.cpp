// run/runtime_modules.cpp — the runtime's side of pass modules coming and going: a
// reloaded module's passes get new objects, and after a frame in which a module faulted
// it goes back to the build it replaced, or its passes stay off until its file changes.
// The rest of Runtime (adopting plans, running frames) is runtime.cpp.
#include "run/runtime.hpp"

#include <set>

#include "kiln/log.hpp"

namespace kiln::run {

// Every enabled pass of module `name` gets an object of the module now registered; the
// old objects go first (their code lives in the old library), and the slots keep their
// textures and parameters.
void Runtime::recreatePassObjects(const std::string& name) {
    for (size_t i = 0; i < slots_.size(); ++i)
        if (slots_[i]->module == name && plan_->passes[i].state != graph::PassState::Disabled)
            createPassObject(*slots_[i], plan_->passes[i]);
}

// The object of a faulted library is abandoned, not destroyed: none of that library's
// code runs again. Its textures keep their last good contents for the passes after it.
void Runtime::retireFaultedObject(PassSlot& slot) {
    (void)slot.pass.release();
    slot.error = slot.library->fault();
    slot.lastRunKey.reset();
}

// After the frame (the plan cannot change under runPass): each module that faulted goes
// back to the build it replaced, with the running parameters, when there is one; or
// its passes stay off until its file changes. Either way the fault is logged once and
// stands in activeErrors until a reload of that module succeeds.
void Runtime::recoverFromFaults() {
    std::set<std::string> faulted;
    faulted.swap(faultedModules_);
    for (const std::string& name : faulted) {
        const ModuleRegistry::Module* current = modules_->find(name);
        if (!current || !current->library->faulted()) continue;
        const ModuleRegistry::Module broken = *current;
        const std::string file = broken.library->sourcePath().filename().string();
        std::string outcome = offUntilChanged(*broken.library);
        if (const ModuleRegistry::Module* previous = modules_->previous(name)) {
            modules_->set(name, *previous);
            std::string errors;
            if (desc_ && loadPipelineDesc(*desc_, errors)) {
                modules_->keepAsPrevious(name, broken);  // faulted: forgets it
                recreatePassObjects(name);
                outcome = "; rolled back to the build loaded before it, until " + file + " changes";
            } else {
                modules_->set(name, broken);
            }
        }
        const std::string message = broken.library->fault() + outcome;
        setExternalError("module:" + name, message);
        if (broken.library->takeFaultToReport()) log::error(message);
    }
}

std::string Runtime::offUntilChanged(const LoadedModule& library) {
    return "; its passes are off until " + library.sourcePath().filename().string() + " changes";
}

bool Runtime::reloadModule(const std::string& name, std::string& error) {
    auto probed = modules_->probe(name);
    if (!probed) {
        error = probed.errorText();
        if (!error.empty() && error.back() == '\n') error.pop_back();
        return false;
    }
    // Validate the running description (the file with the debug view's edits) against
    // the new declaration before touching anything.
    std::optional<ModuleRegistry::Module> old;
    if (const ModuleRegistry::Module* m = modules_->find(name)) old = *m;
    modules_->set(name, *probed);
    std::string errors;
    if (desc_ && !loadPipelineDesc(*desc_, errors)) {
        if (old) modules_->set(name, *old);
        else modules_->erase(name);
        error = errors;
        return false;
    }
    if (old) modules_->keepAsPrevious(name, *old);
    recreatePassObjects(name);
    return true;
}

}  // namespace kiln::run
