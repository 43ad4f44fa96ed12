#include "kiln/module_loader.hpp"

#include <dlfcn.h>
#include <elf.h>
#include <unistd.h>

#include <algorithm>
#include <cstring>
#include <fstream>

#include "kiln/names.hpp"
#include "kiln/log.hpp"

namespace fs = std::filesystem;

namespace kiln {

LoadedModule::~LoadedModule() {
    if (handle_) dlclose(handle_);
    std::error_code ec;
    if (!loadedCopy_.empty()) fs::remove(loadedCopy_, ec);
}

ModuleLoader::ModuleLoader(std::vector<fs::path> dirs) : dirs_(std::move(dirs)) {
    const char* tmp = std::getenv("TMPDIR");
    scratch_ = fs::path(tmp && *tmp ? tmp : "/tmp") / ("kiln-modules-" + std::to_string(getpid()));
}

ModuleLoader::~ModuleLoader() {
    // Copies still mapped by live modules are removed by their LoadedModule; the
    // directory goes when it is empty.
    std::error_code ec;
    fs::remove(scratch_, ec);
}

std::vector<std::string> ModuleLoader::available() const {
    std::vector<std::string> names;
    for (auto& dir : dirs_) {
        std::error_code ec;
        for (auto& entry : fs::directory_iterator(dir, ec)) {
            std::string f = entry.path().filename().string();
            if (f.rfind("libpass_", 0) == 0 && f.size() > 11 && f.ends_with(".so")) {
                std::string n = f.substr(8, f.size() - 11);
                if (isValidName(n) && std::find(names.begin(), names.end(), n) == names.end()) names.push_back(n);
            }
        }
    }
    std::sort(names.begin(), names.end());
    return names;
}

fs::path ModuleLoader::locate(const std::string& name) const {
    if (!isValidName(name)) return {};
    for (auto& dir : dirs_) {
        std::error_code ec;
        fs::path p = dir / fileNameFor(name);
        if (fs::is_regular_file(p, ec)) return p;
    }
    return {};
}

namespace {
std::string joined(const std::vector<std::string>& v) {
    std::string s;
    for (auto& x : v) s += (s.empty() ? "" : ", ") + x;
    return s.empty() ? "none" : s;
}

// dlopen maps a file's segments as its headers say; a file cut short (an interrupted
// build, `truncate`) then faults with SIGBUS on first touch, inside dlopen. So the
// headers are checked against the file's real size first: a 64-bit ELF shared object
// whose program headers, loadable segments and section headers all lie inside it.
bool checkElf(const fs::path& file, std::string& error) {
    std::ifstream in(file, std::ios::binary);
    std::error_code ec;
    const uint64_t size = fs::file_size(file, ec);
    Elf64_Ehdr eh{};
    if (!in || ec || size < sizeof eh || !in.read(reinterpret_cast<char*>(&eh), sizeof eh)) {
        error = "not a shared library (" + std::to_string(ec ? 0 : size) + " bytes, no ELF header)";
        return false;
    }
    if (std::memcmp(eh.e_ident, ELFMAG, SELFMAG) != 0 || eh.e_ident[EI_CLASS] != ELFCLASS64 || eh.e_type != ET_DYN) {
        error = "not a 64-bit ELF shared library";
        return false;
    }
    auto inside = [&](uint64_t offset, uint64_t count, uint64_t each) {
        return offset <= size && count <= (size - offset) / std::max<uint64_t>(each, 1);
    };
    if (eh.e_phentsize != sizeof(Elf64_Phdr) || !inside(eh.e_phoff, eh.e_phnum, sizeof(Elf64_Phdr)) ||
        !inside(eh.e_shoff, eh.e_shnum, eh.e_shentsize)) {
        error = "truncated: its headers reach past the end of the file (" + std::to_string(size) +
                " bytes; an interrupted build?)";
        return false;
    }
    in.seekg(static_cast<std::streamoff>(eh.e_phoff));
    for (int i = 0; i < eh.e_phnum; ++i) {
        Elf64_Phdr ph{};
        if (!in.read(reinterpret_cast<char*>(&ph), sizeof ph)) break;
        if (ph.p_type == PT_LOAD && !inside(ph.p_offset, ph.p_filesz, 1)) {
            error = "truncated: segment " + std::to_string(i) + " ends at byte " +
                    std::to_string(ph.p_offset + ph.p_filesz) + " of a " + std::to_string(size) +
                    "-byte file (an interrupted build?)";
            return false;
        }
    }
    return true;
}
}  // namespace

bool ModuleLoader::checkFile(const fs::path& file, std::string& why) { return checkElf(file, why); }

std::shared_ptr<LoadedModule> ModuleLoader::load(const std::string& name, std::string& error) {
    if (!isValidName(name)) {
        error = "module name \"" + name + "\" is not valid: a module is named by " + std::string(kNameRule) + ", no path, \"..\" or suffix";
        return nullptr;
    }
    fs::path source = locate(name);
    if (source.empty()) {
        std::string dirs;
        for (auto& d : dirs_) dirs += (dirs.empty() ? "" : ", ") + d.string();
        auto names = available();
        std::string hint = nearestName(name, names);
        error = "no module \"" + name + "\" (" + fileNameFor(name) + ") in " + (dirs.empty() ? "no module directory" : dirs) +
                (hint.empty() ? "" : "; did you mean \"" + hint + "\"?") + " (available: " + joined(names) + ")";
        return nullptr;
    }

    // A private copy under a name never used before: dlopen would hand back a cached
    // handle for a path it has seen, and the linker may rewrite the original.
    std::error_code ec;
    fs::create_directories(scratch_, ec);
    fs::path copy = scratch_ / (fileNameFor(name) + "." + std::to_string(++serial_));
    fs::path tmp = copy;
    tmp += ".tmp";
    fs::copy_file(source, tmp, fs::copy_options::overwrite_existing, ec);
    if (!ec) fs::rename(tmp, copy, ec);
    if (ec) {
        error = source.string() + ": cannot copy for loading: " + ec.message();
        return nullptr;
    }

    auto module = std::shared_ptr<LoadedModule>(new LoadedModule());
    module->name_ = name;
    module->source_ = source;
    module->loadedCopy_ = copy;  // removed by ~LoadedModule, loaded or not
    // The copy is what dlopen maps, so the copy is what is checked.
    std::string why;
    if (!checkElf(copy, why)) {
        error = source.string() + ": cannot load: " + why;
        return nullptr;
    }
    module->handle_ = dlopen(copy.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (!module->handle_) {
        const char* why = dlerror();
        error = source.string() + ": cannot load: " + (why ? why : "dlopen failed");
        return nullptr;
    }
    using EntryFn = const KilnPassModule* (*)();
    auto entry = reinterpret_cast<EntryFn>(dlsym(module->handle_, "kiln_pass_module"));
    if (!entry) {
        error = source.string() + ": not a Kiln pass module (no exported symbol kiln_pass_module)";
        return nullptr;
    }
    const KilnPassModule* desc = entry();
    if (!desc) {
        error = source.string() + ": kiln_pass_module() returned null";
        return nullptr;
    }
    if (desc->abiVersion != kPassAbiVersion) {
        error = source.string() + ": built for pass ABI version " + std::to_string(desc->abiVersion) +
                ", this host speaks version " + std::to_string(kPassAbiVersion) + "; rebuild the module";
        return nullptr;
    }
    if (!desc->name || name != desc->name || !desc->create || !desc->destroy) {
        error = source.string() + ": descriptor names module \"" + (desc->name ? desc->name : "(null)") +
                "\" or lacks a factory; the file name and KILN_PASS_MODULE name must match";
        return nullptr;
    }
    module->desc_ = desc;
    return module;
}

PassPtr ModuleLoader::create(const std::shared_ptr<LoadedModule>& module, std::string& error) {
    Pass* raw = nullptr;
    try {
        raw = module->desc_->create();
    } catch (const std::exception& e) {
        error = module->source_.string() + ": factory failed: " + e.what();
        return nullptr;
    } catch (...) {
        error = module->source_.string() + ": factory failed with an unknown exception";
        return nullptr;
    }
    if (!raw) {
        error = module->source_.string() + ": factory returned null";
        return nullptr;
    }
    // The deleter holds the module, so the code that destroys the pass stays mapped.
    auto destroy = module->desc_->destroy;
    return PassPtr(raw, [module, destroy](Pass* p) { destroy(p); });
}

}  // namespace kiln
