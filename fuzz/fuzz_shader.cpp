// Fuzz target: the shader #include resolver. The input is a shader, optionally followed
// by more files ("\n//@file NAME\n" starts one), written into a copy of shaders/ with
// symlinks that point out of it. Preprocessing must never read a file outside the root:
// every dependency is inside it and no text from outside appears in the output.
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "kiln/shader.hpp"

namespace fs = std::filesystem;

namespace {
constexpr const char* kSecret = "OUTSIDE_THE_SHADER_ROOT";

void require(bool ok, const char* what, const std::string& detail = {}) {
    if (ok) return;
    std::fprintf(stderr, "fuzz_shader: invariant broken: %s\n%.2000s\n", what, detail.c_str());
    std::abort();
}

void write(const fs::path& p, const std::string& text) { std::ofstream(p, std::ios::binary | std::ios::trunc) << text; }

// base/root: a copy of the project's shaders; base/outside.glsl and base/secret/ hold
// the marker; root/escape.glsl and root/escape_dir link out of the root.
struct Sandbox {
    fs::path base, root;
    Sandbox() {
        const char* tmp = std::getenv("TMPDIR");
        base = fs::path(tmp && *tmp ? tmp : "/tmp") / ("kiln-fuzz-shader-" + std::to_string(getpid()));
        fs::remove_all(base);
        fs::create_directories(base / "secret");
        fs::copy(fs::path(KILN_SOURCE_DIR) / "shaders", base / "root", fs::copy_options::recursive);
        root = fs::canonical(base / "root");
        write(base / "outside.glsl", std::string("// ") + kSecret + "\n");
        write(base / "secret/inc.glsl", std::string("// ") + kSecret + "\n");
        fs::create_symlink(base / "outside.glsl", root / "escape.glsl");
        fs::create_directory_symlink(base / "secret", root / "escape_dir");
        fs::create_symlink("loop_b.glsl", root / "loop_a.glsl");
        fs::create_symlink("loop_a.glsl", root / "loop_b.glsl");
    }
    ~Sandbox() {
        std::error_code ec;
        fs::remove_all(base, ec);
    }
};

// A name the input may create: [a-z0-9_./], no "..", not absolute, short.
bool safeName(const std::string& n) {
    if (n.empty() || n.size() > 40 || n[0] == '/' || n.find("..") != std::string::npos) return false;
    for (char c : n)
        if (!((c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_' || c == '.' || c == '/')) return false;
    return n.find("escape") == std::string::npos && n.find("loop_") == std::string::npos;
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    static Sandbox box;
    const std::string input(reinterpret_cast<const char*>(data), size);
    const std::string marker = "\n//@file ";
    std::vector<fs::path> written;
    size_t at = input.find(marker);
    write(box.root / "fuzz_main.frag", input.substr(0, at));
    written.push_back(box.root / "fuzz_main.frag");
    while (at != std::string::npos) {
        const size_t nameStart = at + marker.size(), nameEnd = input.find('\n', nameStart);
        if (nameEnd == std::string::npos) break;
        const std::string name = input.substr(nameStart, nameEnd - nameStart);
        at = input.find(marker, nameEnd);
        if (!safeName(name)) continue;
        std::error_code ec;
        const fs::path p = box.root / "fuzz" / name;
        fs::create_directories(p.parent_path(), ec);
        if (ec || fs::is_directory(p, ec)) continue;
        write(p, input.substr(nameEnd + 1, at == std::string::npos ? std::string::npos : at - nameEnd - 1));
        written.push_back(p);
    }
    kiln::ShaderLibrary lib({box.root});
    kiln::PreprocessedSource out;
    kiln::ShaderError error;
    const bool ok = lib.preprocess("fuzz_main.frag", {{"FUZZ", "1"}}, out, error);
    for (const fs::path& dep : out.dependencies) {
        std::error_code ec;
        const fs::path real = fs::weakly_canonical(dep, ec);
        const std::string r = real.string(), rootText = box.root.string() + "/";
        require(r.compare(0, rootText.size(), rootText) == 0, "read a file outside the shader root", r);
    }
    // (The fuzzer learns the marker from this very comparison and may type it itself.)
    if (input.find(kSecret) == std::string::npos)
        require(out.text.find(kSecret) == std::string::npos, "text from outside the root in the output");
    if (!ok) require(error.toString().size() <= 2000, "an error longer than 2000 bytes", error.toString().substr(0, 2000));
    std::error_code ec;
    fs::remove_all(box.root / "fuzz", ec);
    return 0;
}
