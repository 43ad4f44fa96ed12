#include "kiln/module_loader.hpp"

#include <dlfcn.h>
#include <elf.h>
#include <fcntl.h>
#include <link.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstring>
#include <fstream>
#include <optional>
#include <string_view>
#include <thread>
#include <vector>

#include "kiln/guard.hpp"
#include "kiln/log.hpp"
#include "kiln/names.hpp"

namespace fs = std::filesystem;

namespace kiln {

LoadedModule::~LoadedModule() {
    if (handle_ && !faulted()) dlclose(handle_);
    std::error_code ec;
    if (!loadedCopy_.empty()) fs::remove(loadedCopy_, ec);
}

void LoadedModule::markFaulted(std::string message) {
    if (fault_.empty()) fault_ = std::move(message);
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
bool checkDynamicSection(std::ifstream& in, const Elf64_Ehdr& eh, uint64_t size, std::string& error);

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
    return checkDynamicSection(in, eh, size, error);
}

// What a linker leaves mid-write can have every header right and a body of zeros.
// dlopen reads the dynamic section first; it must hold the string and symbol tables,
// and the strings must name the entry point.
bool checkDynamicSection(std::ifstream& in, const Elf64_Ehdr& eh, uint64_t size, std::string& error) {
    std::vector<Elf64_Phdr> headers(eh.e_phnum);
    in.clear();
    in.seekg(static_cast<std::streamoff>(eh.e_phoff));
    if (!in.read(reinterpret_cast<char*>(headers.data()), std::streamsize(headers.size() * sizeof(Elf64_Phdr)))) {
        error = "unreadable program headers";
        return false;
    }
    auto dynamic = std::find_if(headers.begin(), headers.end(), [](const Elf64_Phdr& p) { return p.p_type == PT_DYNAMIC; });
    if (dynamic == headers.end() || dynamic->p_filesz < sizeof(Elf64_Dyn) || dynamic->p_offset > size ||
        dynamic->p_filesz > size - dynamic->p_offset) {
        error = "no dynamic section inside the file";
        return false;
    }
    std::vector<Elf64_Dyn> entries(dynamic->p_filesz / sizeof(Elf64_Dyn));
    in.seekg(static_cast<std::streamoff>(dynamic->p_offset));
    in.read(reinterpret_cast<char*>(entries.data()), std::streamsize(entries.size() * sizeof(Elf64_Dyn)));
    uint64_t strtab = 0, strsz = 0;
    bool symtab = false, hash = false;
    for (const Elf64_Dyn& d : entries) {
        if (d.d_tag == DT_NULL) break;
        if (d.d_tag == DT_STRTAB) strtab = d.d_un.d_ptr;
        if (d.d_tag == DT_STRSZ) strsz = d.d_un.d_val;
        if (d.d_tag == DT_SYMTAB) symtab = true;
        if (d.d_tag == DT_HASH || d.d_tag == DT_GNU_HASH) hash = true;
    }
    const std::string written = " (a file still being written, or overwritten with zeros?)";
    if (!strtab || !strsz || !symtab || !hash) {
        error = "its dynamic section lacks the symbol tables" + written;
        return false;
    }
    // The string table's address to a file offset, through the segment that maps it.
    auto segment = std::find_if(headers.begin(), headers.end(), [&](const Elf64_Phdr& p) {
        return p.p_type == PT_LOAD && strtab >= p.p_vaddr && strtab + strsz <= p.p_vaddr + p.p_filesz;
    });
    if (segment == headers.end() || strsz > (64u << 20)) {
        error = "its dynamic string table lies outside the file" + written;
        return false;
    }
    std::string strings(strsz, '\0');
    in.seekg(static_cast<std::streamoff>(segment->p_offset + (strtab - segment->p_vaddr)));
    if (!in.read(strings.data(), std::streamsize(strsz)) ||
        strings.find(std::string_view("kiln_pass_module\0", 17)) == std::string::npos) {
        error = "not a Kiln pass module (no exported symbol kiln_pass_module)";
        return false;
    }
    return true;
}

// The addresses of a loaded library's executable segments (one, for a module).
guard::CodeRange codeOf(void* handle) {
    struct link_map* map = nullptr;
    if (dlinfo(handle, RTLD_DI_LINKMAP, &map) != 0 || !map) return {};
    struct Search {
        ElfW(Addr) base;
        guard::CodeRange range;
    } search{map->l_addr, {}};
    dl_iterate_phdr(
        [](dl_phdr_info* info, size_t, void* data) {
            auto* s = static_cast<Search*>(data);
            if (info->dlpi_addr != s->base) return 0;
            for (int i = 0; i < info->dlpi_phnum; ++i) {
                const ElfW(Phdr)& ph = info->dlpi_phdr[i];
                if (ph.p_type != PT_LOAD || !(ph.p_flags & PF_X)) continue;
                const uintptr_t begin = info->dlpi_addr + ph.p_vaddr, end = begin + ph.p_memsz;
                const bool first = s->range.begin >= s->range.end;
                s->range = {first ? begin : std::min(s->range.begin, begin), first ? end : std::max(s->range.end, end)};
            }
            return 1;
        },
        &search);
    return search.range;
}

constexpr int kThrewStatus = 3;

// Runs what dlopen runs — the library's static initialisers — and its entry point in a
// child process, where a crash or a hang costs nothing: the host learns the signal and
// never maps the library. Returns the fault, or nothing when the child came back (an
// ordinary dlopen error is left for the host's own dlopen to report).
std::optional<std::string> trialOpen(const fs::path& file) {
    const pid_t child = fork();
    if (child < 0) return std::nullopt;  // no process to spare: the guard is what is left
    if (child == 0) {
        for (int sig : guard::kFatalSignals) signal(sig, SIG_DFL);
        const int devnull = open("/dev/null", O_WRONLY);  // its messages are the host's to give
        if (devnull >= 0) dup2(devnull, STDERR_FILENO), dup2(devnull, STDOUT_FILENO);
        // Nothing may unwind out of here: the child would go on as a copy of the host.
        try {
            void* handle = dlopen(file.c_str(), RTLD_NOW | RTLD_LOCAL);
            if (!handle) _exit(2);
            using EntryFn = const KilnPassModule* (*)();
            if (auto entry = reinterpret_cast<EntryFn>(dlsym(handle, "kiln_pass_module"))) entry();
        } catch (...) {
            _exit(kThrewStatus);
        }
        _exit(0);
    }
    const auto limit = guard::watchdogLimit().count() > 0 ? guard::watchdogLimit() : std::chrono::milliseconds(60000);
    const auto deadline = std::chrono::steady_clock::now() + limit;
    int status = 0;
    for (auto pause = std::chrono::microseconds(200);; pause = std::min(pause * 2, std::chrono::microseconds(20000))) {
        const pid_t done = waitpid(child, &status, WNOHANG);
        if (done == child) break;
        if (done < 0) return std::nullopt;
        if (std::chrono::steady_clock::now() >= deadline) {
            kill(child, SIGKILL);
            waitpid(child, &status, 0);
            return guard::overrun(limit);
        }
        std::this_thread::sleep_for(pause);
    }
    if (WIFSIGNALED(status)) return guard::signalName(WTERMSIG(status));
    if (WIFEXITED(status) && WEXITSTATUS(status) == kThrewStatus) return std::string("an exception");
    return std::nullopt;
}
// dlopen and kiln_pass_module(): the descriptor, or null with `opened`/`hasEntry` saying
// how far it got.
const KilnPassModule* openAndDescribe(const fs::path& copy, void*& handle, bool& opened, bool& hasEntry) {
    using EntryFn = const KilnPassModule* (*)();
    handle = dlopen(copy.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (!handle) return nullptr;
    opened = true;
    auto entry = reinterpret_cast<EntryFn>(dlsym(handle, "kiln_pass_module"));
    if (!entry) return nullptr;
    hasEntry = true;
    return entry();
}

// What is wrong with what kiln_pass_module() gave, if anything: a message, or "".
std::string descriptorProblem(const fs::path& source, const std::string& name, bool hasEntry,
                              const KilnPassModule* desc) {
    if (!hasEntry) return source.string() + ": not a Kiln pass module (no exported symbol kiln_pass_module)";
    if (!desc) return source.string() + ": kiln_pass_module() returned null";
    if (desc->abiVersion != kPassAbiVersion)
        return source.string() + ": built for pass ABI version " + std::to_string(desc->abiVersion) +
               ", this host speaks version " + std::to_string(kPassAbiVersion) + "; rebuild the module";
    if (!desc->name || name != desc->name || !desc->create || !desc->destroy)
        return source.string() + ": descriptor names module \"" + (desc->name ? desc->name : "(null)") +
               "\" or lacks a factory; the file name and KILN_PASS_MODULE name must match";
    return "";
}

}  // namespace

bool ModuleLoader::checkFile(const fs::path& file, std::string& why) { return checkElf(file, why); }

std::shared_ptr<LoadedModule> ModuleLoader::load(const std::string& name, std::string& error) {
    if (!isValidName(name)) {
        error = "module name \"" + name + "\" is not valid: a module is named by " + std::string(kNameRule) + ", no path, \"..\" or suffix";
        return nullptr;
    }
    const fs::path source = locate(name);
    if (source.empty()) {
        error = notFound(name);
        return nullptr;
    }
    const fs::path copy = privateCopy(source, name, error);
    if (copy.empty()) return nullptr;

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
    const auto cannotLoad = [&](const std::string& fault) {
        return source.string() + ": cannot load: " + fault + " in its static initialisers or kiln_pass_module()";
    };
    if (auto fault = trialOpen(copy)) {
        error = cannotLoad(*fault);
        return nullptr;
    }
    // The child came through; the guard is for a library that behaves otherwise here.
    // Not watched: dlopen holds the dynamic loader's lock (the child timed the loops).
    const KilnPassModule* desc = nullptr;
    bool opened = false, hasEntry = false;
    if (auto fault = guard::guarded([&] { desc = openAndDescribe(copy, module->handle_, opened, hasEntry); },
                                    guard::kUnwatched)) {
        error = cannotLoad(*fault);
        module->markFaulted(error);
        return nullptr;
    }
    if (!opened) {
        const char* why = dlerror();
        error = source.string() + ": cannot load: " + (why ? why : "dlopen failed");
        return nullptr;
    }
    module->code_ = codeOf(module->handle_);
    if (std::string refused = descriptorProblem(source, name, hasEntry, desc); !refused.empty()) {
        error = refused;
        return nullptr;
    }
    module->desc_ = desc;
    return module;
}

std::string ModuleLoader::notFound(const std::string& name) const {
    std::string dirs;
    for (auto& d : dirs_) dirs += (dirs.empty() ? "" : ", ") + d.string();
    const auto names = available();
    const std::string hint = nearestName(name, names);
    return "no module \"" + name + "\" (" + fileNameFor(name) + ") in " + (dirs.empty() ? "no module directory" : dirs) +
           (hint.empty() ? "" : "; did you mean \"" + hint + "\"?") + " (available: " + joined(names) + ")";
}

fs::path ModuleLoader::privateCopy(const fs::path& source, const std::string& name, std::string& error) const {
    static std::atomic<unsigned> serial{0};
    std::error_code ec;
    fs::create_directories(scratch_, ec);
    const fs::path copy = scratch_ / (fileNameFor(name) + "." + std::to_string(++serial));
    fs::path tmp = copy;
    tmp += ".tmp";
    fs::copy_file(source, tmp, fs::copy_options::overwrite_existing, ec);
    if (!ec) fs::rename(tmp, copy, ec);
    if (!ec) return copy;
    error = source.string() + ": cannot copy for loading: " + ec.message();
    return {};
}

PassPtr ModuleLoader::create(const std::shared_ptr<LoadedModule>& module, std::string& error) {
    Pass* raw = nullptr;
    if (auto fault = guard::guarded([&] { raw = module->desc_->create(); }, module->watch())) {
        const std::string what = module->source_.filename().string() + ": " + *fault + " in create()";
        if (!guard::unwound(*fault)) module->markFaulted(what);
        error = module->source_.string() + ": factory failed: " + *fault + " in create()";
        return nullptr;
    }
    if (!raw) {
        error = module->source_.string() + ": factory returned null";
        return nullptr;
    }
    // The deleter holds the module, so the code that destroys the pass stays mapped.
    auto destroy = module->desc_->destroy;
    return PassPtr(raw, [module, destroy](Pass* p) {
        if (module->faulted()) return;  // its code is not called again: the object is lost
        if (auto fault = guard::guarded([&] { destroy(p); }, module->watch()))
            module->markFaulted(module->source_.filename().string() + ": " + *fault + " in destroy()");
    });
}

}  // namespace kiln
