// kiln/data_root.hpp — where Kiln's own files are: the data root (shaders/, pipelines/,
// scenes/, scripts/plot.py) and the shipped pass modules. An installed Kiln finds them
// relative to its executable (<prefix>/bin → <prefix>/share/kiln, <prefix>/lib/kiln/
// modules: the same under any --prefix, and in the .deb); one run from its build tree
// finds the source tree it was built from and the build's modules/. Header-only: the
// host, kiln-sim and the benchmark commands all use it (link the kiln_paths target).
#pragma once

#include <filesystem>
#include <string>
#include <system_error>

#if !defined(KILN_SOURCE_DIR) || !defined(KILN_BUILD_MODULE_DIR) || !defined(KILN_BIN_TO_DATA) || !defined(KILN_BIN_TO_MODULES)
#error "link the kiln_paths target (top-level CMakeLists.txt)"
#endif

namespace kiln {

struct ShippedFiles {
    std::filesystem::path data;     // holds shaders/, pipelines/, scenes/, scripts/
    std::filesystem::path modules;  // libpass_<name>.so of the shipped passes
    bool installed = false;         // found next to the executable, not in the source tree
    std::string describe() const {
        return (installed ? "the installation, " : "the source tree Kiln was built from, ") + data.string() +
               " (modules: " + modules.string() + ")";
    }
};

inline ShippedFiles shippedFiles() {
    namespace fs = std::filesystem;
    std::error_code ec;
    const fs::path executable = fs::read_symlink("/proc/self/exe", ec);
    if (!ec) {
        const fs::path bin = executable.parent_path();
        const fs::path data = (bin / KILN_BIN_TO_DATA).lexically_normal();
        if (fs::is_regular_file(data / "pipelines/default.json", ec))
            return {data, (bin / KILN_BIN_TO_MODULES).lexically_normal(), true};
    }
    return {KILN_SOURCE_DIR, KILN_BUILD_MODULE_DIR, false};
}

}  // namespace kiln
