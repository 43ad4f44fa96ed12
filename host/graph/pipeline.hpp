// graph/pipeline.hpp — the pipeline file as plain data, and its reader/writer.
//
// A pipeline file (pipelines/*.json, schema in pipelines/pipeline.schema.json):
//
//     {
//       "note": "prose goes in note fields; comments are not JSON",
//       "output": "composite.color",
//       "passes": [
//         { "id": "gbuffer", "module": "gbuffer" },
//         { "id": "shadow", "module": "shadow", "params": { "size": 2048 } },
//         { "id": "composite", "module": "composite", "enabled": true,
//           "inputs": { "albedo": "gbuffer.albedo", "shadow_map": "shadow.depth" },
//           "params": { "exposure": 1.0 } }
//       ]
//     }
//
// parsePipeline() checks only the *shape* of the file (JSON syntax, key names, value
// types) and keeps everything else as written; the meaning (do the modules, slots,
// outputs and parameters exist, do the kinds match) is compile()'s job
// (graph/compiler.hpp), because it needs the modules' declarations. A PipelineDesc
// can also be built or edited in code (the debug view's enable toggles and parameter
// widgets do), and written back with writePipeline().
//
// No nlohmann types appear here: parameter values are kept as ParamLiteral.
#pragma once

#include "graph/diagnostic.hpp"
#include "kiln/declare.hpp"
#include "kiln/json_text.hpp"

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace kiln::graph {

// A parameter value as written in the file, before it is checked against the
// declaration (which is where "2048.5 is not an int" is decided).
struct ParamLiteral {
    enum class Type : uint8_t { Null, Bool, Int, Float, String, Array, Object };
    Type type = Type::Null;
    bool b = false;
    int64_t i = 0;
    double f = 0.0;                   // also set for Int, so a float param can read it
    std::string s;                    // String
    std::vector<ParamLiteral> items;  // Array
    std::string text;                 // the value as compact JSON, for messages

    static ParamLiteral of(const ParamValue&);  // for the debug view writing params back
};
const char* toString(ParamLiteral::Type);  // "bool", "int", "float", "string", "array", ...

struct PassDesc {
    std::string id;
    std::string module;
    bool enabled = true;
    std::vector<std::pair<std::string, ParamLiteral>> params;  // in file order
    std::vector<std::pair<std::string, std::string>> inputs;   // slot → "<pass id>.<output>" ("" from null)
    std::string note;

    // Only in a file that extends another (PipelineDesc::extends), to say how it changes
    // the base: drop the base's pass of this id; put an added or moved pass before or
    // after the pass of that id. "enabled" written, so a changed pass takes it.
    bool remove = false;
    std::string placeBefore, placeAfter;
    bool enabledGiven = false;
    // After resolveExtends: where the entry that last wrote this pass is, for messages
    // (the file of the chain and the index in its "passes"); empty file: fileName's own.
    struct Origin {
        std::string file;
        int index = -1;
    } origin;
};

// A parameter value typed on a command line (--set PASS.PARAM=VALUE): VALUE as JSON
// (1024, 0.5, true, [1, 0.5, 0.2], "text"), or a bare word as a string (an enum choice).
ParamLiteral parseParamLiteral(const std::string& value);
// "PASS.PARAM=VALUE" split at its first '.' and the first '=' after it (VALUE as typed,
// for parseParamLiteral); nullopt when a part is missing or empty before the '='.
struct ParamOverride {
    std::string text;  // as typed, for messages
    std::string pass, param, value;
};
std::optional<ParamOverride> parseParamOverride(const std::string& text);

// Sets (or adds, at the end) the file's value of parameter `name`.
void setParamLiteral(PassDesc&, const std::string& name, const ParamValue&);

struct PipelineDesc {
    std::string fileName;             // for messages; "pipelines/default.json"
    std::string extends;              // "extends": the base file, relative to this one; "" once resolved
    std::string schema;               // "$schema", kept so writing back keeps it
    std::string note;
    std::string output;               // "<pass id>.<output>"; "" when missing
    std::vector<PassDesc> passes;     // in execution order (= file order)

    // Index of the pass with this id, or -1 (the first one if ids repeat).
    int find(const std::string& id) const;
};

// Reads a pipeline. Errors: JSON syntax (file:line:col), duplicate keys, unknown keys
// (with the nearest known key), values of the wrong JSON type. All are collected.
// The largest pipeline file read (as a scene file: sim's kMaxSceneFileBytes); a larger
// one, or /dev/zero, is refused by name before it fills memory.
inline constexpr size_t kMaxPipelineFileBytes = size_t(16) << 20;

Result<PipelineDesc> parsePipeline(const std::string& text, const std::string& fileName);

// "extends": "default.json" makes a file the changes to another (the path relative to the
// file; a chain of up to 16). Each of its passes' entries, by id:
//   - a pass the base lacks, with a "module": added, at the end or "before"/"after" a pass;
//   - a pass the base has, with a "module": replaced whole (and moved, with before/after);
//   - a pass the base has, without one: its "params" and "inputs" set over the base's,
//     key by key (null takes one away: a parameter back to its default, an input
//     unbound), and "enabled" and "note" where written;
//   - "remove": true: the base's pass dropped.
// "output" and the notes, where written, replace the base's. Errors are the file's of the
// chain they are in; each resolved pass keeps its entry's place (PassDesc::origin), so
// the compiler's errors point there too.
// The reader returns a file's text, or false and why not.
using PipelineReader = std::function<bool(const std::string& file, std::string& text, std::string& why)>;
// The one from disk: a pipeline file read whole within kMaxPipelineFileBytes, a device or
// a directory refused by name (every pipeline file, extended ones too, is read so).
bool readPipelineFile(const std::string& file, std::string& text, std::string& why);
// `desc` as parsePipeline gave it; on success the whole pipeline, with `extends` cleared.
// A relative "extends" is looked for beside the file, then in each of `searchDirs` (the
// shipped pipelines/), as #include "..." is: "default.json" works from anywhere.
// `chain`: the files read, `desc`'s first (all of them want watching).
Result<PipelineDesc> resolveExtends(PipelineDesc desc, const PipelineReader&, std::vector<std::string>* chain = nullptr,
                                    const std::vector<std::string>& searchDirs = {});

// Writes a pipeline back as pretty JSON (2-space indent, keys in the canonical
// order; "enabled" only when false, empty params/inputs left out).
std::string writePipeline(const PipelineDesc&);

// Rewrites `original` (a pipeline file's text, which parses to some PipelineDesc) so that
// it describes `edited`, touching only what differs — for the debug view's "write back",
// where writePipeline() would reorder keys and reflow the whole file.
//
// Value edits, the only ones made:
//   - a changed parameter value is replaced in place; the bytes around it are untouched.
//     Values are written as writePipeline() writes them (compact JSON, floats in their
//     shortest round-tripping form, flat arrays as [1.0, 0.5, 0.25]). A value that is the
//     same is left as written: an int in the file that `edited` holds as the equal float
//     (`1` vs 1.0; a float parameter accepts an int) stays `1`; the other way (2048.0 in
//     the file, the int 2048 edited) is rewritten, since an int parameter refuses 2048.0.
//   - a parameter the file lacks is appended to the pass's "params" object, copying the
//     spacing and indentation of the object's last key (a one-line object stays one line);
//     when the pass has no "params", `"params": { ... }` (one line) is added right after
//     its "module" key, spaced like that key; an empty `{}` becomes `{ "name": value }`.
//   - "enabled": a pass turned off that has no "enabled" key gets `"enabled": false` after
//     its "module" key; an existing "enabled" value is replaced in place, so a pass turned
//     back on keeps an explicit `"enabled": true` (not removed: removing a key means
//     guessing which comma and whitespace go with it, and the explicit key shows where to
//     toggle it again).
// A file that extends another (PipelineDesc::extends) is refused: its passes are partly
// the other file's. Anything else that differs is not a value edit — passes added, removed or reordered, a
// pass's id, module, inputs (including their order) or note, the pipeline's output, note
// or $schema, a parameter the file has but `edited` lacks, a parameter named twice in
// `edited`, a value JSON cannot hold (NaN/Inf, invalid UTF-8) — and nothing is returned:
// `error` says why, and the caller falls back to writePipeline(). `original` not parsing
// is reported the same way. Parameter order in `edited` does not matter (matched by
// name); new ones are appended in `edited`'s order. With nothing to change, the result is
// `original`, byte for byte. `edited.fileName` is ignored.
std::optional<std::string> patchPipelineText(const std::string& original, const PipelineDesc& edited,
                                             std::string& error);

// Byte offset (0-based) → 1-based line and column (column counts bytes); shared with the
// scene loader.
using json_text::lineColumn;

}  // namespace kiln::graph
