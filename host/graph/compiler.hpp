// graph/compiler.hpp — pipeline → validated, ordered, culled Plan.
//
//     #include "graph/compiler.hpp"
//     using namespace kiln::graph;
//
//     CompileOptions opt;
//     opt.resolve = [&](const std::string& module) -> Result<kiln::PassDeclaration> {
//         ...load/lookup the module, return its declare() or Result<...>::failure(msg)
//     };
//     opt.availableModules = {"gbuffer", "shadow", "composite", ...};  // for suggestions
//     opt.requested = {"gbuffer.normal"};   // what the debug view shows / --dump wants
//
//     Result<Plan> plan = compileText(text, "pipelines/default.json", opt);
//     if (!plan) { print(plan.errorText()); keep the running plan; }
//     else       { print(plan->table()); for (int i : plan->runOrder()) ... }
//
// The stages, in order (each collects every error it finds and carries on):
//   1. parse     text → PipelineDesc (graph/pipeline.hpp); syntax errors stop here
//   2. resolve   ids (unique, [a-z0-9_]+), modules → declarations (once per module),
//                declarations sanity-checked (size params exist and are ints, ...)
//   3. bind      parameters typed and range-checked over the declared defaults;
//                inputs bound to earlier passes' outputs, kinds checked; disabled
//                producers replaced by the input's fallback (or an error when the
//                input is required); the graph output checked
//   4. cull      walk back from the graph output and the requested textures
//   5. sign      per-pass signature for resource reuse across recompiles
//
// Order is file order. Reading an output of a later pass (or of the pass itself) is an
// error, so the graph is acyclic by construction and needs no topological sort: the
// user reorders passes by reordering the file.
//
// Diagnostics for a *disabled* pass (its own params/inputs) are warnings: a pass is
// often disabled precisely because it is broken, and it does not run.
#pragma once

#include "graph/diagnostic.hpp"
#include "graph/pipeline.hpp"
#include "graph/plan.hpp"
#include "kiln/declare.hpp"
#include "kiln/names.hpp"

#include <functional>
#include <string_view>
#include <string>
#include <vector>

namespace kiln::graph {

// Returns the declaration of a module by name, or a failure whose message is passed
// through to the user (prefixed by the pass's JSON path). Called at most once per
// distinct module name per compile, only for names matching [a-z0-9_]+ and, when
// CompileOptions::availableModules is non-empty, only for names in that list (others
// are reported as unknown modules with the nearest available name). An exception
// thrown by the resolver is reported like a failure.
using ModuleResolver = std::function<Result<PassDeclaration>(const std::string& module)>;

struct CompileOptions {
    ModuleResolver resolve;
    std::vector<std::string> availableModules;  // for "did you mean"
    // "pass.output" (or "pass.internal") strings the debug view shows or --dump wants;
    // they un-cull their producers. Ones that don't exist become Plan::warnings.
    std::vector<std::string> requested;
    // compileText only: where a relative "extends" is looked for after beside the file.
    std::vector<std::string> pipelineSearchDirs;
};

// On success, the Plan (with Plan::warnings). On failure, errors() holds every error
// and warning found, sorted by their place in the file ("output" first).
Result<Plan> compile(const PipelineDesc&, const CompileOptions&);
// Checks a value against its declaration as compile() does a file's (type, range,
// choices); the value as the parameter holds it, or nullopt and `problem` says why.
std::optional<ParamValue> checkParamValue(const ParamValue&, const ParamDecl&, std::string& problem);
std::optional<ParamValue> checkParamLiteral(const ParamLiteral&, const ParamDecl&, std::string& problem);

// parsePipeline + resolveExtends (the files it extends read from disk, relative to
// `fileName`, then in CompileOptions::pipelineSearchDirs) + compile.
Result<Plan> compileText(const std::string& text, const std::string& fileName, const CompileOptions&);

}  // namespace kiln::graph
