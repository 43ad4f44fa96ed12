#include "kiln/shader.hpp"

#include <algorithm>
#include <cctype>
#include <cstring>
#include <fstream>
#include <sstream>

#include "kiln/log.hpp"
#include "kiln/names.hpp"

namespace fs = std::filesystem;

namespace kiln {

std::string ShaderError::toString() const {
    std::string where = file.empty() ? "<shader>" : file;
    if (line > 0) where += ":" + std::to_string(line);
    return where + ": " + message;
}

std::string ProgramBuild::errorText() const {
    std::string s;
    for (auto& e : errors) s += e.toString() + "\n";
    return s;
}

ShaderLibrary::ShaderLibrary(std::vector<fs::path> roots) {
    for (auto& r : roots) {
        std::error_code ec;
        fs::path canon = fs::weakly_canonical(r, ec);
        roots_.push_back(ec ? r : canon);
    }
}

namespace {
bool isInside(const fs::path& root, const fs::path& p) {
    auto r = root.begin(), q = p.begin();
    for (; r != root.end(); ++r, ++q)
        if (q == p.end() || *r != *q) return false;
    return true;
}

// Shader lines are user input of any length: they are scanned by hand, in one pass,
// never with std::regex (whose matcher recurses per character and overflows the stack
// on a line of some 40 000 characters).

// "  #  include rest" → {"include", " rest"}; not a directive → empty name.
struct Directive {
    std::string_view name, rest;
};
Directive directiveOf(std::string_view line) {
    size_t i = line.find_first_not_of(" \t");
    if (i == std::string_view::npos || line[i] != '#') return {};
    i = line.find_first_not_of(" \t", i + 1);
    if (i == std::string_view::npos) return {};
    size_t j = i;
    while (j < line.size() && (std::isalnum(static_cast<unsigned char>(line[j])) || line[j] == '_')) ++j;
    return {line.substr(i, j - i), line.substr(j)};
}

// The file name of `"name"`, optionally followed by a // comment; empty when malformed.
std::string quotedName(std::string_view rest) {
    const size_t open = rest.find_first_not_of(" \t");
    if (open == std::string_view::npos || rest[open] != '"') return {};
    const size_t close = rest.find('"', open + 1);
    if (close == std::string_view::npos || close == open + 1) return {};
    const size_t after = rest.find_first_not_of(" \t", close + 1);
    if (after != std::string_view::npos && rest.substr(after, 2) != "//") return {};
    return std::string(rest.substr(open + 1, close - open - 1));
}

// Reads the unsigned number at `s[i]`, advancing `i`; false when there is none.
bool readNumber(std::string_view s, size_t& i, size_t& value) {
    const size_t start = i;
    value = 0;
    while (i < s.size() && std::isdigit(static_cast<unsigned char>(s[i])) && i - start < 9) value = value * 10 + size_t(s[i++] - '0');
    return i > start;
}

// A compiler log line "S:L(C): msg" (Mesa) or "S(L) : msg" (NVIDIA) → L and msg.
bool parseLogLine(std::string_view line, size_t& lineNo, std::string& message) {
    size_t i = 0, number = 0, column = 0;
    if (!readNumber(line, i, number) || i >= line.size()) return false;
    if (line[i] == ':') {  // Mesa
        ++i;
        if (!readNumber(line, i, lineNo) || i >= line.size() || line[i] != '(') return false;
        ++i;
        if (!readNumber(line, i, column) || line.substr(i, 2) != "):") return false;
        i += 2;
    } else if (line[i] == '(') {  // NVIDIA
        ++i;
        if (!readNumber(line, i, lineNo) || i >= line.size() || line[i] != ')') return false;
        i = line.find(':', i);
        if (i == std::string_view::npos) return false;
        ++i;
    } else {
        return false;
    }
    const size_t text = line.find_first_not_of(" \t", i);
    message = text == std::string_view::npos ? std::string() : std::string(line.substr(text));
    return true;
}

bool readFile(const fs::path& p, std::string& out) {
    std::ifstream in(p, std::ios::binary);
    if (!in) return false;
    std::ostringstream ss;
    ss << in.rdbuf();
    out = ss.str();
    return true;
}
}  // namespace

fs::path ShaderLibrary::resolve(const std::string& relative) const {
    for (auto& root : roots_) {
        std::error_code ec;
        fs::path p = fs::weakly_canonical(root / relative, ec);
        if (ec || !isInside(root, p)) continue;
        if (fs::is_regular_file(p, ec)) return p;
    }
    return {};
}

std::string ShaderLibrary::displayPath(const fs::path& absolute) const {
    for (auto& root : roots_)
        if (isInside(root, absolute))
            return (root.filename() / absolute.lexically_relative(root)).generic_string();
    return absolute.generic_string();
}

namespace {
struct Preprocessor {
    const ShaderLibrary& lib;
    PreprocessedSource& out;
    ShaderError& error;
    std::vector<fs::path> stack;

    int fileId(const fs::path& p) {
        std::string d = lib.displayPath(p);
        auto it = std::find(out.files.begin(), out.files.end(), d);
        if (it != out.files.end()) return static_cast<int>(it - out.files.begin());
        out.files.push_back(d);
        return static_cast<int>(out.files.size() - 1);
    }

    void emit(const std::string& line, int file, int lineNo) {
        out.text += line + "\n";
        out.lines.push_back({file, lineNo});
    }

    // "a.frag -> b.glsl -> a.frag": the include stack and `file`.
    std::string chainTo(const fs::path& file) const {
        std::string chain;
        for (auto& f : stack) chain += lib.displayPath(f) + " -> ";
        return chain + lib.displayPath(file);
    }

    // What `#include "name"` in `file` reads: beside `file` when that stays inside a
    // shader root, else the first root that has it; empty when none does.
    fs::path includeTarget(const fs::path& file, const std::string& name) const {
        std::error_code ec;
        const fs::path local = fs::weakly_canonical(file.parent_path() / name, ec);
        bool insideRoots = false;
        for (auto& r : lib.roots()) insideRoots |= isInside(r, local);
        if (!ec && insideRoots && fs::is_regular_file(local, ec)) return local;
        return lib.resolve(name);
    }

    // Appends `file` to out.text; `header` (the #version + defines) goes right after
    // the #version line of the top-level file.
    bool include(const fs::path& file, const std::string* header) {
        if (std::find(stack.begin(), stack.end(), file) != stack.end()) {
            error = {lib.displayPath(stack.back()), 0, "#include cycle: " + chainTo(file)};
            return false;
        }
        if (std::find(out.dependencies.begin(), out.dependencies.end(), file) != out.dependencies.end())
            return true;  // included once per stage
        std::string text;
        if (!readFile(file, text)) {
            error = {lib.displayPath(file), 0, "cannot read file"};
            return false;
        }
        out.dependencies.push_back(file);
        stack.push_back(file);
        const int id = fileId(file);
        std::istringstream lines(text);
        std::string line;
        int lineNo = 0;
        bool sawVersion = header == nullptr;
        while (std::getline(lines, line)) {
            ++lineNo;
            if (!line.empty() && line.back() == '\r') line.pop_back();
            const Directive directive = directiveOf(line);
            if (!sawVersion && directive.name == "version") {
                emit(line, id, lineNo);
                std::istringstream defines(*header);
                std::string define;
                while (std::getline(defines, define)) emit(define, id, lineNo);  // blamed on #version
                sawVersion = true;
                continue;
            }
            if (directive.name == "include") {
                const std::string name = quotedName(directive.rest);
                if (name.empty()) {
                    error = {lib.displayPath(file), lineNo, "malformed #include (expected #include \"file\")"};
                    return false;
                }
                const fs::path target = includeTarget(file, name);
                if (target.empty()) {
                    error = {lib.displayPath(file), lineNo, "#include \"" + elide(name) + "\": file not found in the shader roots"};
                    return false;
                }
                if (!include(target, nullptr)) return false;
                continue;
            }
            emit(line, id, lineNo);
        }
        if (!sawVersion) {
            error = {lib.displayPath(file), 1, "no #version line"};
            return false;
        }
        stack.pop_back();
        return true;
    }
};
}  // namespace

bool ShaderLibrary::preprocess(const std::string& relativePath, const Defines& defines, PreprocessedSource& out,
                               ShaderError& error) const {
    out = {};
    fs::path file = resolve(relativePath);
    if (file.empty()) {
        error = {relativePath, 0, "shader not found in the shader roots"};
        return false;
    }
    std::string header;
    for (auto& [k, v] : defines) header += "#define " + k + " " + v + "\n";
    Preprocessor pp{*this, out, error, {}};
    return pp.include(file, &header);
}

std::vector<ShaderError> mapInfoLog(const std::string& log, const PreprocessedSource& src) {
    std::vector<ShaderError> errors;
    std::istringstream lines(log);
    std::string line;
    while (std::getline(lines, line)) {
        if (line.empty()) continue;
        size_t at = 0;
        std::string message;
        if (parseLogLine(line, at, message)) {
            // The source-string number is ignored: the driver gets one string and
            // Mesa does not track it reliably anyway; the line table is exact.
            if (at >= 1 && at <= src.lines.size()) {
                const SourceLine& where = src.lines[at - 1];
                errors.push_back({src.files[static_cast<size_t>(where.file)], where.line, message});
            } else {
                errors.push_back({src.files.empty() ? "" : src.files[0], 0, message});
            }
        } else {
            errors.push_back({src.files.empty() ? "" : src.files[0], 0, line});
        }
    }
    return errors;
}

namespace {
GLenum stageOf(const std::string& path) {
    auto ext = fs::path(path).extension().string();
    if (ext == ".vert") return GL_VERTEX_SHADER;
    if (ext == ".frag") return GL_FRAGMENT_SHADER;
    if (ext == ".geom") return GL_GEOMETRY_SHADER;
    if (ext == ".comp") return GL_COMPUTE_SHADER;
    if (ext == ".tesc") return GL_TESS_CONTROL_SHADER;
    if (ext == ".tese") return GL_TESS_EVALUATION_SHADER;
    return 0;
}

std::string infoLog(GLuint object, bool isProgram) {
    GLint len = 0;
    if (isProgram)
        glGetProgramiv(object, GL_INFO_LOG_LENGTH, &len);
    else
        glGetShaderiv(object, GL_INFO_LOG_LENGTH, &len);
    std::string s(static_cast<size_t>(std::max(len, 1)), '\0');
    if (isProgram)
        glGetProgramInfoLog(object, len, nullptr, s.data());
    else
        glGetShaderInfoLog(object, len, nullptr, s.data());
    s.resize(std::strlen(s.c_str()));
    return s;
}

// OpenGL 4.5 core's guaranteed minimums (the specification's table of implementation
// limits) for what a shader names by binding: GL_MAX_IMAGE_UNITS and
// GL_MAX_COMBINED_IMAGE_UNIFORMS, GL_MAX_{FRAGMENT,COMPUTE}_IMAGE_UNIFORMS,
// GL_MAX_SHADER_STORAGE_BUFFER_BINDINGS and GL_MAX_{FRAGMENT,COMPUTE}_SHADER_STORAGE_BLOCKS.
constexpr GLint kGuaranteedImageUnits = 8, kGuaranteedStorageBindings = 8;

bool isImageType(GLint type) { return type >= GL_IMAGE_1D && type <= GL_UNSIGNED_INT_IMAGE_2D_MULTISAMPLE_ARRAY; }

// The query that asks whether a stage references a resource, per stage.
struct StageRef {
    GLenum referencedBy, stage;
};
constexpr StageRef kStageRefs[] = {{GL_REFERENCED_BY_VERTEX_SHADER, GL_VERTEX_SHADER},
                                   {GL_REFERENCED_BY_TESS_CONTROL_SHADER, GL_TESS_CONTROL_SHADER},
                                   {GL_REFERENCED_BY_TESS_EVALUATION_SHADER, GL_TESS_EVALUATION_SHADER},
                                   {GL_REFERENCED_BY_GEOMETRY_SHADER, GL_GEOMETRY_SHADER},
                                   {GL_REFERENCED_BY_FRAGMENT_SHADER, GL_FRAGMENT_SHADER},
                                   {GL_REFERENCED_BY_COMPUTE_SHADER, GL_COMPUTE_SHADER}};

// Each image uniform (every array element) or storage block of a linked program: its
// binding and the stages that use it.
struct BoundResource {
    std::string name;
    GLint binding = 0;
    std::vector<GLenum> stages;
};

std::vector<BoundResource> boundResources(GLuint program, GLenum interface) {
    std::vector<BoundResource> out;
    GLint count = 0, nameLength = 0;
    glGetProgramInterfaceiv(program, interface, GL_ACTIVE_RESOURCES, &count);
    glGetProgramInterfaceiv(program, interface, GL_MAX_NAME_LENGTH, &nameLength);
    for (GLint i = 0; i < count; ++i) {
        std::string name(size_t(std::max(nameLength, 1)), '\0');
        glGetProgramResourceName(program, interface, GLuint(i), nameLength, nullptr, name.data());
        name.resize(std::strlen(name.c_str()));
        auto referencingStages = [&] {
            std::vector<GLenum> stages;
            for (const StageRef& ref : kStageRefs) {
                GLint used = 0;
                glGetProgramResourceiv(program, interface, GLuint(i), 1, &ref.referencedBy, 1, nullptr, &used);
                if (used) stages.push_back(ref.stage);
            }
            return stages;
        };
        if (interface == GL_SHADER_STORAGE_BLOCK) {
            const GLenum prop = GL_BUFFER_BINDING;
            GLint binding = 0;
            glGetProgramResourceiv(program, interface, GLuint(i), 1, &prop, 1, nullptr, &binding);
            out.push_back({name, binding, referencingStages()});
            continue;
        }
        // Every other uniform (most of them) is passed over before its stages are asked.
        const GLenum props[] = {GL_TYPE, GL_LOCATION, GL_ARRAY_SIZE};
        GLint values[3] = {};
        glGetProgramResourceiv(program, interface, GLuint(i), 3, props, 3, nullptr, values);
        if (!isImageType(values[0]) || values[1] < 0) continue;
        const std::vector<GLenum> stages = referencingStages();
        const bool array = name.ends_with("[0]");
        if (array) name.resize(name.size() - 3);
        for (GLint element = 0; element < std::max(values[2], 1); ++element) {
            GLint unit = 0;
            glGetUniformiv(program, values[1] + element, &unit);
            out.push_back({array ? str(name, "[", element, "]") : name, unit, stages});
        }
    }
    return out;
}

// A stage that compiled, with its preprocessed source (for file:line lookups).
struct CompiledStage {
    GLenum stage;
    PreprocessedSource source;
};

// Where a resource is declared: the first line of a stage's source that names it with
// a binding qualifier ("... binding = N ... u_name" or a block "buffer Name"), as that
// stage's file and line; else the stage's own file.
ShaderError declaredAt(const std::vector<CompiledStage>& stages, const std::vector<GLenum>& usedBy,
                       const std::string& resource) {
    const std::string name = resource.substr(0, resource.find('['));
    auto isIdentifier = [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; };
    for (const CompiledStage& stage : stages) {
        // No referencing stage reported (Mesa's answer for a storage block here): any stage.
        if (!usedBy.empty() && std::find(usedBy.begin(), usedBy.end(), stage.stage) == usedBy.end()) continue;
        const PreprocessedSource& src = stage.source;
        std::istringstream text(src.text);
        std::string line;
        for (size_t at = 0; std::getline(text, line); ++at) {
            if (line.find("binding") == std::string::npos) continue;
            for (size_t pos = line.find(name); pos != std::string::npos; pos = line.find(name, pos + 1)) {
                const size_t end = pos + name.size();
                if ((pos > 0 && isIdentifier(line[pos - 1])) || (end < line.size() && isIdentifier(line[end])))
                    continue;
                if (at < src.lines.size())
                    return {src.files[size_t(src.lines[at].file)], src.lines[at].line, ""};
            }
        }
        return {src.files.empty() ? "" : src.files[0], 0, ""};
    }
    return {stages.empty() || stages[0].source.files.empty() ? "" : stages[0].source.files[0], 0, ""};
}

// What the linked program uses beyond kGuaranteed*, each where it is declared.
std::vector<ShaderError> portabilityIssues(const std::vector<CompiledStage>& stages, GLuint program) {
    std::vector<ShaderError> issues;
    struct Kind {
        GLenum interface;
        const char *what, *units, *consequence;
        GLint guaranteed;
    };
    for (const Kind& kind :
         {Kind{GL_UNIFORM, "image", "image unit", "NVIDIA's image units stop there: it will not link on its driver",
               kGuaranteedImageUnits},
          Kind{GL_SHADER_STORAGE_BLOCK, "storage block", "storage buffer binding",
               "a driver at the minimum will not link it", kGuaranteedStorageBindings}}) {
        const std::vector<BoundResource> resources = boundResources(program, kind.interface);
        for (const BoundResource& r : resources)
            if (r.binding >= kind.guaranteed) {
                ShaderError issue = declaredAt(stages, r.stages, r.name);
                issue.message = str(kind.what, " '", r.name, "' is bound to ", kind.units, " ", r.binding,
                                    "; OpenGL 4.5 guarantees 0-", kind.guaranteed - 1, " only (", kind.consequence, ")");
                issues.push_back(std::move(issue));
            }
        for (const CompiledStage& stage : stages) {
            if (stage.stage != GL_FRAGMENT_SHADER && stage.stage != GL_COMPUTE_SHADER) continue;
            const auto used = std::count_if(resources.begin(), resources.end(), [&](const BoundResource& r) {
                return std::find(r.stages.begin(), r.stages.end(), stage.stage) != r.stages.end();
            });
            if (used > kind.guaranteed)
                issues.push_back({stage.source.files.empty() ? "" : stage.source.files[0], 0,
                                  str("uses ", used, " ", kind.what, "s; OpenGL 4.5 guarantees a ",
                                      stage.stage == GL_COMPUTE_SHADER ? "compute" : "fragment", " shader ",
                                      kind.guaranteed, " only")});
        }
    }
    return issues;
}

}  // namespace

ProgramBuild buildProgram(const ShaderLibrary& lib, const ProgramDesc& desc) {
    ProgramBuild build;
    std::vector<gl::ShaderHandle> shaders;
    std::vector<CompiledStage> compiled;
    for (auto& stagePath : desc.stages) {
        GLenum stage = stageOf(stagePath);
        if (!stage) {
            build.errors.push_back({stagePath, 0, "unknown shader stage (extension must be .vert .frag .geom .comp .tesc .tese)"});
            continue;
        }
        PreprocessedSource src;
        ShaderError err;
        if (!lib.preprocess(stagePath, desc.defines, src, err)) {
            build.errors.push_back(err);
            for (auto& d : src.dependencies) build.dependencies.push_back(d);
            continue;
        }
        for (auto& d : src.dependencies) build.dependencies.push_back(d);
        gl::ShaderHandle sh(glCreateShader(stage));
        const char* text = src.text.c_str();
        glShaderSource(sh.id(), 1, &text, nullptr);
        glCompileShader(sh.id());
        GLint ok = 0;
        glGetShaderiv(sh.id(), GL_COMPILE_STATUS, &ok);
        if (!ok) {
            auto errs = mapInfoLog(infoLog(sh.id(), false), src);
            build.errors.insert(build.errors.end(), errs.begin(), errs.end());
            continue;
        }
        shaders.push_back(std::move(sh));
        compiled.push_back({stage, std::move(src)});
    }
    if (!build.errors.empty()) return build;

    gl::ProgramHandle program(glCreateProgram());
    for (auto& sh : shaders) glAttachShader(program.id(), sh.id());
    glLinkProgram(program.id());
    for (auto& sh : shaders) glDetachShader(program.id(), sh.id());
    GLint linked = 0;
    glGetProgramiv(program.id(), GL_LINK_STATUS, &linked);
    if (!linked) {
        // Link errors carry no location; attribute them to the first stage.
        build.errors.push_back({lib.displayPath(lib.resolve(desc.stages.front())), 0,
                                "link failed: " + infoLog(program.id(), true)});
        return build;
    }
    gl::label(GL_PROGRAM, program.id(), desc.debugName.empty() ? desc.stages.front() : desc.debugName);
    build.portability = portabilityIssues(compiled, program.id());
    build.program = std::move(program);
    return build;
}

}  // namespace kiln
