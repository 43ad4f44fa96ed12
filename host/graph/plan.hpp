// graph/plan.hpp — the compiled graph: what runs, in which order, reading what.
//
// A Plan lists every pass of the pipeline file in file order (which is execution
// order), each with its state:
//   Run       it is executed (subject to the host's version-based skipping);
//   Culled    valid, but nothing it writes reaches the graph output or a texture the
//             debug view shows / --dump wants; `reason` says so;
//   Disabled  "enabled": false; it was removed from the graph, and optional inputs it
//             fed read their declared fallback instead (Binding::lost says from whom).
// Culled and disabled passes stay in the list so the debug view can show them and
// their parameters; the host simply skips them.
//
// Each pass carries a `signature` over (module, resolved params, bindings, declared
// texture shapes). After a recompile, a pass whose id and signature are unchanged can
// keep its textures (diffPlans); anything else gets fresh ones.
#pragma once

#include "graph/diagnostic.hpp"
#include "kiln/declare.hpp"

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace kiln::graph {

struct NamedParam {
    std::string name;
    ParamValue value;
};

// A pass's parameter values, in declaration order: declared defaults overlaid with the
// pipeline file's values, each already checked against its ParamDecl.
struct ResolvedParams {
    std::vector<NamedParam> values;

    const ParamValue* find(std::string_view name) const;
    ParamValue* find(std::string_view name);
    // Typed access; nullptr when absent or of another type.
    template <class T>
    const T* get(std::string_view name) const {
        const ParamValue* v = find(name);
        return v ? std::get_if<T>(v) : nullptr;
    }
};

// "true", "2048", "0.5", "\"aces\"", "[1, 0.5, 0]" — JSON-like, exact for floats.
std::string formatParamValue(const ParamValue&);

struct Binding {
    std::string slot;               // the input's declared name
    int producer = -1;              // index into Plan::passes; -1: reads `fallback`
    std::string output;             // the producer's output name
    Fallback fallback = Fallback::Black;  // meaningful when producer < 0
    std::string lost;               // "shadow.depth" when the file bound it to a disabled pass

    bool bound() const { return producer >= 0; }
};

enum class PassState : uint8_t { Run, Culled, Disabled };
const char* toString(PassState);  // "run", "culled", "disabled"

struct PlannedPass {
    std::string id;
    std::string module;
    PassDeclaration decl;
    ResolvedParams params;
    std::vector<Binding> bindings;  // one per declared input, in declaration order
    PassState state = PassState::Run;
    std::string reason;             // why culled/disabled; "" for Run
    std::string signature;          // readable; equal signatures ⇒ same textures
    uint64_t signatureHash = 0;     // FNV-1a of `signature`
    // Parallel to decl.outputs: whether something reads the output — a running pass
    // bound to it, the graph output, a requested texture (PassContext::isRead).
    std::vector<bool> outputRead;

    bool runs() const { return state == PassState::Run; }
    const Binding* binding(std::string_view slot) const;
    const TextureDecl* output(std::string_view name) const;
    int outputIndex(std::string_view name) const;    // into decl.outputs; -1: no such output
    bool outputIsRead(std::string_view name) const;  // outputRead's entry; false: no such output
    const TextureDecl* texture(std::string_view name) const;  // output or internal
};

struct TextureRef {
    int pass = -1;          // index into Plan::passes
    std::string name;       // output (or internal) name
    bool valid() const { return pass >= 0; }
};

struct Extent {
    int w = 1, h = 1, d = 1;
    bool operator==(const Extent&) const = default;
};

// How a 3D FromParam texture (a voxel grid) follows the scene's voxel volume: its side
// along axis a is the parameter halved shift[a] times (kiln::voxelGridShift), so a
// room's grid has as many cells across its height as the room is tall. All zero: a cube.
struct GridShape {
    int shift[3] = {0, 0, 0};
    bool operator==(const GridShape&) const = default;
};

struct Plan {
    std::string fileName;
    std::vector<PlannedPass> passes;     // file order = execution order
    TextureRef output;                   // the graph output (a colour 2D output)
    std::vector<std::string> requested;  // the viewed/dumped textures that exist
    std::vector<Diagnostic> warnings;    // requested textures that don't exist, ...

    int find(std::string_view id) const;       // index or -1
    std::vector<int> runOrder() const;         // indices of the passes that run
    // The extent of pass `pass`'s output or internal `name` for a graph output of
    // outW×outH, following FromInput sizes through the bindings ({1,1,1} if unknown).
    Extent extentOf(int pass, std::string_view name, int outW, int outH, const GridShape& grid = {}) const;

    // Fixed-width text table: #, id, module, state (and why), inputs
    // (slot←pass.output or slot←fallback:black), outputs (name format size-rule).
    std::string table() const;
    // Graphviz: a node per pass (culled greyed, disabled dashed), an edge per bound
    // (or lost) input labelled with its slot, and the graph output as a final node.
    std::string dot() const;
};

// The size of an output/internal texture for a graph output of outW×outH:
// RelativeToOutput: round(scale × out), at least 1 (2D);
// Fixed: width × height (× depth for 3D);
// FromParam: a square (2D) whose side is the int parameter (at least 1), or a grid (3D)
//   that long on its longest side and shortened along each axis by `grid`;
// FromInput: `input` (the extent of what is bound to the slot) × scale, 1 when null.
// compile() guarantees FromParam names an int parameter; if it does not, the side is 1.
Extent resolveSize(const TextureDecl&, int outW, int outH, const ResolvedParams&, const Extent* input = nullptr,
                   const GridShape& grid = {});

// "1x", "0.5x", "256x256", "64x64x64", "size(=2048)" — as the table prints it.
std::string describeSize(const TextureDecl&, const ResolvedParams&);

// What a recompile changed, by pass id. `unchanged`: in both plans with the same
// signature (keep its textures); `changed`: in both, signature differs; `added` /
// `removed`: only in the new / old plan.
struct PlanDiff {
    std::vector<std::string> unchanged, changed, added, removed;
    bool isUnchanged(std::string_view id) const;
};
PlanDiff diffPlans(const Plan& before, const Plan& after);

}  // namespace kiln::graph
