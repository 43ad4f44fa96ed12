// kiln/shader.hpp — GLSL with #include, compiled into programs whose errors point at
// the file that holds the line.
//
// `#include "file.glsl"` resolves relative to the including file, then inside the
// shader roots; nothing outside the roots is read. Each file is included once per
// stage (like #pragma once); including a file that is already being included is a
// cycle, reported with the chain. The expanded text keeps a table from each of its
// lines to (file, line), and the driver's `0:LINE(COL): message` is mapped through it
// to `shaders/<dir>/<file>:LINE: message`. (No `#line N <id>` directives: Mesa 22
// reports source-string 0 for some errors inside included code, e.g. an undeclared
// identifier, so the id cannot be trusted; the line over the whole text can.)
#pragma once

#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "kiln/gl.hpp"

namespace kiln {

struct ShaderError {
    std::string file;  // display path, e.g. "shaders/common/scene.glsl" (empty if unknown)
    int line = 0;      // 1-based, 0 if unknown
    std::string message;
    std::string toString() const;
};

using Defines = std::vector<std::pair<std::string, std::string>>;

struct SourceLine {
    int file = 0;  // index into PreprocessedSource::files
    int line = 0;  // 1-based line in that file
};

struct PreprocessedSource {
    std::string text;                 // ready for glShaderSource
    std::vector<std::string> files;   // file index → display path
    std::vector<SourceLine> lines;    // line of `text` (0-based) → where it came from
    std::vector<std::filesystem::path> dependencies;  // absolute paths of every file read
};

class ShaderLibrary {
public:
    explicit ShaderLibrary(std::vector<std::filesystem::path> roots);

    const std::vector<std::filesystem::path>& roots() const { return roots_; }
    // Absolute path of a shader given relative to a root, or empty if none has it
    // (or it tries to leave the roots).
    std::filesystem::path resolve(const std::string& relative) const;
    std::string displayPath(const std::filesystem::path& absolute) const;

    // Resolves includes and inserts defines after #version. On failure returns false
    // and fills `error` (missing file, cycle, a malformed #include).
    bool preprocess(const std::string& relativePath, const Defines& defines, PreprocessedSource& out,
                    ShaderError& error) const;

private:
    std::vector<std::filesystem::path> roots_;
};

// Maps a driver info log (Mesa's `0:12(5): error: …`, NVIDIA's `0(12) : error …`)
// through the line table of the text that was compiled.
std::vector<ShaderError> mapInfoLog(const std::string& log, const PreprocessedSource& src);

struct ProgramDesc {
    std::vector<std::string> stages;  // relative paths; stage from the extension
                                      // (.vert .frag .geom .comp .tesc .tese)
    Defines defines;
    std::string debugName;
};

struct ProgramBuild {
    gl::ProgramHandle program;        // empty on failure
    std::vector<ShaderError> errors;
    // What the program uses beyond OpenGL 4.5's guaranteed minimums (image units and
    // storage blocks: 8): it links here (llvmpipe allows 32) but not on a driver at the
    // minimum, as NVIDIA's image units are. Not an error: the program runs here.
    std::vector<ShaderError> portability;
    std::vector<std::filesystem::path> dependencies;  // every file of every stage
    bool ok() const { return bool(program); }
    std::string errorText() const;    // errors one per line
};

// Compiles and links a new program; never touches an existing one, so a caller can
// keep its last good program when this fails.
ProgramBuild buildProgram(const ShaderLibrary&, const ProgramDesc&);

}  // namespace kiln
