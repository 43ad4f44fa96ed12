// The graph compiler: resolve → bind → cull → sign (see graph/compiler.hpp).
#include "graph/compiler.hpp"

#include "kiln/hash.hpp"
#include "kiln/names.hpp"

#include <algorithm>
#include <climits>
#include <cmath>
#include <cstdio>
#include <exception>
#include <map>
#include <optional>
#include <set>

namespace kiln::graph {

namespace {

bool isIdentifier(std::string_view s) {
    if (s.empty()) return false;
    for (char c : s)
        if (!((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_')) return false;
    return true;
}

std::string q(std::string_view s) { return "\"" + elide(s) + "\""; }

std::string num(double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%g", v);
    return buf;
}

// "Shadow Map" → "shadow_map": what a bad id probably meant.
std::string sanitizeName(std::string_view s) {
    std::string out;
    for (char c : s) {
        if (c >= 'A' && c <= 'Z') out += static_cast<char>(c - 'A' + 'a');
        else if ((c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_') out += c;
        else if (!out.empty() && out.back() != '_') out += '_';
    }
    while (!out.empty() && out.back() == '_') out.pop_back();
    return out;
}

std::string describe(const TextureDecl& t) {
    return std::string(toString(t.kind)) + " (" + toString(t.format) + ")";
}

// "<pass id>.<output>" split at its one dot; false when malformed.
bool splitBinding(const std::string& text, std::string& pass, std::string& output) {
    const size_t dot = text.find('.');
    if (dot == std::string::npos || dot == 0 || dot + 1 == text.size() || text.find('.', dot + 1) != std::string::npos)
        return false;
    pass = text.substr(0, dot);
    output = text.substr(dot + 1);
    return true;
}

// The parameter `name` of a declaration; null when it declares none.
const ParamDecl* declaredParam(const PassDeclaration& d, const std::string& name) {
    auto it = std::find_if(d.params.begin(), d.params.end(), [&](const ParamDecl& p) { return p.name == name; });
    return it == d.params.end() ? nullptr : &*it;
}

// Problems in one output or internal texture declaration.
void checkTexture(const char* what, const TextureDecl& t, const PassDeclaration& d, std::vector<std::string>& problems) {
    const std::string name = std::string(what) + " " + q(t.name);
    if ((t.kind == TextureKind::Depth2D) != isDepthFormat(t.format))
        problems.push_back(name + " is " + toString(t.kind) + " but has format " + toString(t.format));
    auto checkScale = [&] {
        if (!(t.size.scale > 0.0f)) problems.push_back(name + " has scale " + num(t.size.scale) + " (must be > 0)");
    };
    auto checkRelative = [&] {  // a multiple of the (2D) output size
        if (t.kind == TextureKind::Color3D) problems.push_back(name + " is 3D but sized relative to the (2D) output");
        checkScale();
    };
    switch (t.size.mode) {
        case SizeRule::Mode::RelativeToOutput: checkRelative(); break;
        case SizeRule::Mode::Fixed:
            if (t.size.width < 1 || t.size.height < 1 || (t.kind == TextureKind::Color3D && t.size.depth < 1))
                problems.push_back(name + " has a fixed size with a side < 1");
            break;
        case SizeRule::Mode::RelativeOverParam: checkRelative(); [[fallthrough]];
        case SizeRule::Mode::FromParam: {
            for (const std::string* source : {&t.size.source, &t.size.capSource}) {
                if (source->empty() && source == &t.size.capSource) continue;  // the cap is optional
                const ParamDecl* side = declaredParam(d, *source);
                if (!side)
                    problems.push_back(name + " takes its size from unknown parameter " + q(*source));
                else if (side->type != ParamType::Int)
                    problems.push_back(name + " takes its size from parameter " + q(*source) + ", which is a " +
                                       toString(side->type) + ", not an int");
            }
            break;
        }
        case SizeRule::Mode::FromInput:
            if (std::none_of(d.inputs.begin(), d.inputs.end(), [&](const InputDecl& in) { return in.name == t.size.source; }))
                problems.push_back(name + " takes its size from unknown input " + q(t.size.source));
            checkScale();
            break;
    }
    if (const std::string& param = t.producedWhen.param; !param.empty()) {
        const ParamDecl* choice = declaredParam(d, param);
        if (!choice || choice->type != ParamType::Enum)
            problems.push_back(name + " is produced when " + q(param) + " has some values, but " +
                               (!choice ? "there is no such parameter" : "it is not an enum"));
        else
            for (const std::string& v : t.producedWhen.values)
                if (std::find(choice->choices.begin(), choice->choices.end(), v) == choice->choices.end())
                    problems.push_back(name + " is produced when " + q(param) + " is " + q(v) +
                                       ", which is not one of its choices");
    }
    if (t.size.tiles < 1) problems.push_back(name + " has " + std::to_string(t.size.tiles) + " tiles (must be >= 1)");
    if (t.mips < 0) problems.push_back(name + " has a negative mip count");
}

// Problems in a module's own declaration: they are bugs in the module, reported
// against the pass that uses it so the user knows which module to fix.
std::vector<std::string> checkDeclaration(const PassDeclaration& d) {
    std::vector<std::string> problems;
    auto checkNames = [&](const char* what, auto const& list, std::set<std::string>& seen) {
        for (const auto& item : list) {
            if (!isIdentifier(item.name))
                problems.push_back(std::string(what) + " " + q(item.name) + " is not a name ([A-Za-z0-9_]+)");
            else if (!seen.insert(item.name).second)
                problems.push_back(std::string(what) + " " + q(item.name) + " is declared twice");
        }
    };
    std::set<std::string> inputs, textures, params;
    checkNames("input", d.inputs, inputs);
    checkNames("output", d.outputs, textures);
    checkNames("internal texture", d.internals, textures);  // outputs and internals share "pass.name"
    checkNames("parameter", d.params, params);

    for (const ParamDecl& p : d.params) {
        static constexpr ParamType kTypeOfIndex[] = {ParamType::Bool, ParamType::Int, ParamType::Float,
                                                     ParamType::Enum, ParamType::Color};
        if (p.def.valueless_by_exception()) continue;
        if (kTypeOfIndex[p.def.index()] != p.type) {
            problems.push_back("parameter " + q(p.name) + " is a " + toString(p.type) + " but its default is a " +
                               toString(kTypeOfIndex[p.def.index()]));
            continue;
        }
        if (p.type == ParamType::Enum) {
            if (p.choices.empty()) problems.push_back("enum parameter " + q(p.name) + " has no choices");
            else if (std::find(p.choices.begin(), p.choices.end(), std::get<std::string>(p.def)) == p.choices.end())
                problems.push_back("enum parameter " + q(p.name) + " defaults to " + q(std::get<std::string>(p.def)) +
                                   ", which is not one of its choices");
        }
        if (p.type == ParamType::Int && !p.intChoices.empty() &&
            std::find(p.intChoices.begin(), p.intChoices.end(), std::get<int>(p.def)) == p.intChoices.end())
            problems.push_back("int parameter " + q(p.name) + " defaults to " + std::to_string(std::get<int>(p.def)) +
                               ", which is not one of its allowed values");
    }

    for (const TextureDecl& t : d.outputs) checkTexture("output", t, d, problems);
    for (const TextureDecl& t : d.internals) checkTexture("internal texture", t, d, problems);
    return problems;
}

// The texture part of a signature: everything that decides how a texture is allocated.
std::string textureKey(const TextureDecl& t) {
    std::string s = t.name + ":" + toString(t.kind) + ":" + toString(t.format) + ":";
    switch (t.size.mode) {
        case SizeRule::Mode::RelativeToOutput: s += "rel" + num(t.size.scale); break;
        case SizeRule::Mode::Fixed:
            s += std::to_string(t.size.width) + "x" + std::to_string(t.size.height) + "x" + std::to_string(t.size.depth);
            break;
        case SizeRule::Mode::FromParam:
            s += "param:" + t.size.source + "*" + num(t.size.scale) + "x" + std::to_string(t.size.tiles);
            break;
        case SizeRule::Mode::FromInput:
            s += "input:" + t.size.source + "*" + num(t.size.scale) + "x" + std::to_string(t.size.tiles);
            break;
        case SizeRule::Mode::RelativeOverParam:
            s += "rel" + num(t.size.scale) + "/" + t.size.source + "^" + t.size.capSource;
            break;
    }
    return s + ":mips" + std::to_string(t.mips);
}

class Compiler {
public:
    static std::optional<ParamValue> checkValue(const ParamLiteral& l, const ParamDecl& d, std::string& problem) {
        return convert(l, d, problem);
    }

    Compiler(const PipelineDesc& desc, const CompileOptions& opt) : desc_(desc), opt_(opt) {}

    Result<Plan> run() {
        const size_t n = desc_.passes.size();
        plan_.fileName = desc_.fileName;
        plan_.passes.resize(n);
        decls_.assign(n, nullptr);

        resolve();
        for (size_t i = 0; i < n; ++i) {
            bindParams(static_cast<int>(i));
            bindInputs(static_cast<int>(i));
        }
        bindOutput();
        cull();
        sign();

        std::stable_sort(diags_.begin(), diags_.end(),
                         [](const auto& a, const auto& b) { return a.first < b.first; });
        std::vector<Diagnostic> all;
        bool failed = false;
        for (auto& [key, d] : diags_) {
            failed = failed || d.isError();
            all.push_back(std::move(d));
        }
        if (failed) return Result<Plan>(std::move(all));
        plan_.warnings = std::move(all);
        return Result<Plan>(std::move(plan_));
    }

private:
    static constexpr int kOutputKey = -1;           // "output" sorts before the passes
    static constexpr int kRequestedKey = INT_MAX;   // viewed textures after everything

    // An error about pass `i`'s own content; a warning when that pass is disabled.
    void passError(int i, const std::string& path, std::string message) {
        const bool disabled = i >= 0 && !desc_.passes[static_cast<size_t>(i)].enabled;
        add(i, disabled ? Diagnostic::Severity::Warning : Diagnostic::Severity::Error, path,
            disabled ? message + " (pass is disabled)" : std::move(message));
    }
    void error(int key, const std::string& path, std::string message) {
        add(key, Diagnostic::Severity::Error, path, std::move(message));
    }
    void warning(int key, const std::string& path, std::string message) {
        add(key, Diagnostic::Severity::Warning, path, std::move(message));
    }
    void add(int key, Diagnostic::Severity s, const std::string& path, std::string message) {
        Diagnostic d;
        d.severity = s;
        d.file = desc_.fileName;
        d.path = path;
        // A pass of an extending pipeline is reported where its entry was written.
        if (key >= 0 && size_t(key) < desc_.passes.size()) {
            const PassDesc::Origin& origin = desc_.passes[size_t(key)].origin;
            const std::string merged = passPath(key);
            if (!origin.file.empty() && path.rfind(merged, 0) == 0) {
                d.file = origin.file;
                d.path = passPath(origin.index) + path.substr(merged.size());
            }
        }
        d.message = std::move(message);
        diags_.emplace_back(key, std::move(d));
    }

    static std::string passPath(int i) { return "passes[" + std::to_string(i) + "]"; }
    bool enabled(int i) const { return desc_.passes[static_cast<size_t>(i)].enabled; }

    // Stage 1: ids and modules.
    void resolve() {
        std::vector<std::string> ids;
        for (size_t i = 0; i < desc_.passes.size(); ++i) {
            const int ii = static_cast<int>(i);
            const PassDesc& p = desc_.passes[i];
            PlannedPass& pp = plan_.passes[i];
            pp.id = p.id;
            pp.module = p.module;

            if (!isValidName(p.id)) {
                const std::string fixed = sanitizeName(p.id);
                error(ii, passPath(ii) + ".id",
                      p.id.empty() ? std::string("empty id: ids must match ") + kNameRule
                                   : "bad id " + q(p.id) + ": ids must match " + kNameRule +
                                         (fixed.empty() ? std::string() : " (e.g. " + q(fixed) + ")"));
            }
            // Even a bad id is indexed, so bindings that name it don't cascade into
            // "no pass" errors; the id error above is enough.
            if (!p.id.empty()) {
                auto [it, inserted] = ids_.emplace(p.id, ii);
                if (!inserted)
                    error(ii, passPath(ii) + ".id",
                          "duplicate id " + q(p.id) + " (first used by " + passPath(it->second) + ")");
                else
                    ids.push_back(p.id);
            }
            decls_[i] = resolveModule(ii);
            if (decls_[i]) pp.decl = *decls_[i];
        }
        idList_ = std::move(ids);
    }

    const PassDeclaration* resolveModule(int i) {
        const PassDesc& p = desc_.passes[static_cast<size_t>(i)];
        const std::string path = passPath(i) + ".module";
        if (!isValidName(p.module)) {
            std::string message = p.module.empty()
                                      ? std::string("empty module name")
                                      : "bad module name " + q(p.module) +
                                            ": a module is named by " + kNameRule + ", no path, no suffix";
            // "../passes/bloom.so" probably meant "bloom".
            std::string base = p.module.substr(p.module.find_last_of("/\\") + 1);
            base = base.substr(0, base.find('.'));
            const auto& avail = opt_.availableModules;
            if (!base.empty() && std::find(avail.begin(), avail.end(), base) != avail.end())
                message += " (did you mean " + q(base) + "?)";
            else if (!base.empty())
                message += suggestion(base, avail, "available modules");
            passError(i, path, message);
            return nullptr;
        }
        const auto& avail = opt_.availableModules;
        if (!avail.empty() && std::find(avail.begin(), avail.end(), p.module) == avail.end()) {
            passError(i, path, "unknown module " + q(p.module) + suggestion(p.module, avail, "available modules"));
            return nullptr;
        }
        auto it = modules_.find(p.module);
        if (it == modules_.end()) it = modules_.emplace(p.module, callResolver(p.module)).first;
        const Resolved& r = it->second;
        if (!r.decl) {
            passError(i, path, "module " + q(p.module) + ": " + r.failure);
            return nullptr;
        }
        for (const std::string& problem : r.problems)
            passError(i, path, "module " + q(p.module) + " declares " + problem +
                                   " (a bug in the module's declaration, not in this file)");
        return &*r.decl;
    }

    struct Resolved {
        std::optional<PassDeclaration> decl;
        std::string failure;
        std::vector<std::string> problems;
    };

    Resolved callResolver(const std::string& module) {
        Resolved r;
        if (!opt_.resolve) {
            r.failure = "no module resolver was given to the graph compiler";
            return r;
        }
        try {
            Result<PassDeclaration> result = opt_.resolve(module);
            if (result) {
                r.decl = std::move(result.value());
                r.problems = checkDeclaration(*r.decl);
            } else {
                for (const Diagnostic& d : result.errors()) {
                    if (!r.failure.empty()) r.failure += "; ";
                    r.failure += d.message;
                }
            }
        } catch (const std::exception& e) {
            r.failure = std::string("resolver threw: ") + e.what();
        }
        return r;
    }

    // Stage 2a: parameters = declared defaults overlaid with the file's values.
    void bindParams(int i) {
        const PassDeclaration* decl = decls_[static_cast<size_t>(i)];
        if (!decl) return;
        const PassDesc& p = desc_.passes[static_cast<size_t>(i)];
        ResolvedParams& out = plan_.passes[static_cast<size_t>(i)].params;
        std::vector<std::string> names;
        for (const ParamDecl& d : decl->params) {
            out.values.push_back({d.name, d.def});
            names.push_back(d.name);
        }
        for (const auto& [name, literal] : p.params) {
            const std::string path = passPath(i) + ".params." + name;
            auto d = std::find_if(decl->params.begin(), decl->params.end(),
                                  [&n = name](const ParamDecl& pd) { return pd.name == n; });
            if (d == decl->params.end()) {
                passError(i, path, "module " + q(p.module) + " has no parameter " + q(name) +
                                       suggestion(name, names, "parameters"));
                continue;
            }
            std::string problem;
            std::optional<ParamValue> v = convert(literal, *d, problem);
            if (!v) {
                passError(i, path, problem);
                continue;
            }
            *out.find(name) = std::move(*v);
        }
    }

    // An int literal within the declaration's range and, if it lists them, its choices.
    static std::optional<ParamValue> convertInt(const ParamLiteral& l, const ParamDecl& d, std::string& problem) {
        const bool ranged = d.min != d.max;
        if (l.i < INT_MIN || l.i > INT_MAX || (ranged && (l.i < d.min || l.i > d.max))) {
            problem = "out of range: " + l.text + " is not in " +
                      (ranged ? "[" + num(d.min) + ", " + num(d.max) + "]"
                              : "[" + std::to_string(INT_MIN) + ", " + std::to_string(INT_MAX) + "]");
            return std::nullopt;
        }
        const int v = static_cast<int>(l.i);
        if (!d.intChoices.empty() && std::find(d.intChoices.begin(), d.intChoices.end(), v) == d.intChoices.end()) {
            problem = l.text + " is not one of the allowed values ";
            for (size_t k = 0; k < d.intChoices.size(); ++k) problem += (k ? ", " : "") + std::to_string(d.intChoices[k]);
            return std::nullopt;
        }
        return ParamValue(v);
    }

    // A string literal that is one of the enum's choices (else the nearest is suggested).
    static std::optional<ParamValue> convertEnum(const ParamLiteral& l, const ParamDecl& d, std::string& problem) {
        if (std::find(d.choices.begin(), d.choices.end(), l.s) != d.choices.end()) return ParamValue(l.s);
        const std::string near = nearestName(l.s, d.choices);
        problem = q(l.s) + " is not one of ";
        for (size_t k = 0; k < d.choices.size(); ++k) problem += (k ? ", " : "") + q(d.choices[k]);
        if (!near.empty()) problem += " (did you mean " + q(near) + "?)";
        return std::nullopt;
    }

    static std::optional<ParamValue> convert(const ParamLiteral& l, const ParamDecl& d, std::string& problem) {
        using T = ParamLiteral::Type;
        auto wrongType = [&](const std::string& expected) {
            problem = "expected " + expected + ", got " + toString(l.type) + " " + l.text;
            if (d.type == ParamType::Int && l.type == T::Float && l.f == std::floor(l.f) && std::abs(l.f) < 1e15)
                problem += " (write it without a fraction: " + num(l.f) + ")";
            return std::nullopt;
        };
        const bool ranged = d.min != d.max;
        auto range = [&] { return "[" + num(d.min) + ", " + num(d.max) + "]"; };
        switch (d.type) {
            case ParamType::Bool:
                if (l.type != T::Bool) return wrongType("bool");
                return ParamValue(l.b);
            case ParamType::Int:
                if (l.type != T::Int) return wrongType("int");
                return convertInt(l, d, problem);
            case ParamType::Float: {
                if (l.type != T::Float && l.type != T::Int) return wrongType("float");
                if (!std::isfinite(l.f) || (ranged && (l.f < d.min || l.f > d.max))) {
                    problem = "out of range: " + l.text + " is not in " + (ranged ? range() : std::string("the finite floats"));
                    return std::nullopt;
                }
                return ParamValue(static_cast<float>(l.f));
            }
            case ParamType::Enum:
                if (l.type != T::String) return wrongType("string (one of the enum's choices)");
                return convertEnum(l, d, problem);
            case ParamType::Color: {
                const bool ok = l.type == T::Array && l.items.size() == 3 &&
                                std::all_of(l.items.begin(), l.items.end(), [](const ParamLiteral& e) {
                                    return (e.type == T::Int || e.type == T::Float) && std::isfinite(e.f);
                                });
                if (!ok) {
                    problem = "expected color [r, g, b] (three numbers), got " +
                              std::string(l.type == T::Array ? "" : std::string(toString(l.type)) + " ") + l.text;
                    return std::nullopt;
                }
                return ParamValue(Color3{static_cast<float>(l.items[0].f), static_cast<float>(l.items[1].f),
                                         static_cast<float>(l.items[2].f)});
            }
        }
        problem = "unsupported parameter type";
        return std::nullopt;
    }

    // Finds pass `id` for a binding; reports and returns -1 when there is none.
    int lookupPass(const std::string& id, int key, const std::string& path) {
        auto it = ids_.find(id);
        if (it != ids_.end()) return it->second;
        const std::string message = "no pass " + q(id) + suggestion(id, idList_, "passes");
        if (key >= 0) passError(key, path, message);
        else error(key, path, message);
        return -1;
    }

    // Stage 2b: inputs. Bindings may only read passes earlier in the file.
    void bindInputs(int i) {
        const PassDesc& p = desc_.passes[static_cast<size_t>(i)];
        const PassDeclaration* decl = decls_[static_cast<size_t>(i)];
        PlannedPass& pp = plan_.passes[static_cast<size_t>(i)];
        std::vector<std::string> slots;
        if (decl) {
            for (const InputDecl& in : decl->inputs) {
                Binding b;
                b.slot = in.name;
                b.fallback = in.fallback;
                pp.bindings.push_back(b);
                slots.push_back(in.name);
            }
        }
        std::set<std::string> mentioned;  // slots the file binds (validly or not)
        for (const auto& [slot, text] : p.inputs) {
            mentioned.insert(slot);
            bindInput(i, slot, text, slots);
        }
        if (!decl) return;
        for (const InputDecl& in : decl->inputs) {
            if (!in.required || mentioned.count(in.name)) continue;
            passError(i, passPath(i) + ".inputs",
                      "required input " + q(in.name) + " (" + toString(in.kind) + ") is not bound" +
                          candidates(i, in.kind));
        }
    }

    // One `"slot": "pass.output"` of pass i's inputs: checked, then bound (or marked lost
    // when its producer is disabled and the input is optional).
    void bindInput(int i, const std::string& slot, const std::string& text, const std::vector<std::string>& slots) {
        const PassDesc& p = desc_.passes[static_cast<size_t>(i)];
        const PassDeclaration* decl = decls_[static_cast<size_t>(i)];
        PlannedPass& pp = plan_.passes[static_cast<size_t>(i)];
        const std::string path = passPath(i) + ".inputs." + slot;
        const InputDecl* in = nullptr;
        if (decl) {
            auto it = std::find_if(decl->inputs.begin(), decl->inputs.end(),
                                   [&](const InputDecl& d) { return d.name == slot; });
            if (it == decl->inputs.end()) {
                passError(i, path, "module " + q(p.module) + " has no input " + q(slot) +
                                       suggestion(slot, slots, "inputs"));
                return;
            }
            in = &*it;
        }
        std::string producerId, outputName;
        if (!splitBinding(text, producerId, outputName)) {
            passError(i, path, "malformed binding " + q(text) + ": expected \"<pass id>.<output>\"" + bindingHint(text));
            return;
        }
        const int j = producerBefore(i, producerId, text, path);
        if (j < 0) return;
        const PassDeclaration* producer = decls_[static_cast<size_t>(j)];
        if (!producer || !in) return;  // already reported against that pass's module
        auto out = std::find_if(producer->outputs.begin(), producer->outputs.end(),
                                [&](const TextureDecl& t) { return t.name == outputName; });
        if (out == producer->outputs.end()) {
            passError(i, path, missingOutput(j, outputName));
            return;
        }
        if (out->kind != in->kind) {
            passError(i, path, "input " + q(slot) + " expects a " + toString(in->kind) + " texture, but " + q(text) +
                                   " is " + describe(*out));
            return;
        }
        if (std::string unfilled = unfilledOutput(j, *out, text, producerId); !unfilled.empty()) {
            passError(i, path, unfilled);
            return;
        }
        Binding& b = *std::find_if(pp.bindings.begin(), pp.bindings.end(),
                                   [&](const Binding& x) { return x.slot == slot; });
        if (!enabled(j)) {
            if (in->required) {
                passError(i, path, q(p.id) + " loses required input " + q(slot) + ": its producer " +
                                       q(producerId) + " (" + passPath(j) + ", which writes " + text +
                                       ") is disabled");
                return;
            }
            b.lost = text;  // optional: read the fallback instead
            return;
        }
        b.producer = j;
        b.output = outputName;
    }

    // The index of the pass that produces `text` for pass i, which must come before i;
    // -1, reported, otherwise.
    int producerBefore(int i, const std::string& producerId, const std::string& text, const std::string& path) {
        const int j = lookupPass(producerId, i, path);
        if (j < 0) return -1;
        if (j == i)
            passError(i, path, "input bound to its own pass (" + q(text) + "): a pass cannot read what it writes");
        else if (j > i)
            passError(i, path, q(text) + " is produced later in the file: move " + q(producerId) + " (" + passPath(j) +
                                   ") before " + q(desc_.passes[static_cast<size_t>(i)].id) + " (" + passPath(i) + ")");
        return j < i ? j : -1;
    }

    // ' (e.g. "gbuffer.albedo")' when a binding names a pass without an output.
    std::string bindingHint(const std::string& text) const {
        auto id = ids_.find(text);
        if (id == ids_.end()) return "";
        const PassDeclaration* d = decls_[static_cast<size_t>(id->second)];
        return d && !d->outputs.empty() ? " (e.g. " + q(text + "." + d->outputs[0].name) + ")" : "";
    }

    // Why output `out` of pass j is not filled with j's parameters (producedWhen), or "".
    std::string unfilledOutput(int j, const TextureDecl& out, const std::string& text, const std::string& producerId) const {
        const ProducedWhen& when = out.producedWhen;
        if (when.param.empty()) return "";
        const std::string* value = plan_.passes[static_cast<size_t>(j)].params.get<std::string>(when.param);
        if (!value || std::find(when.values.begin(), when.values.end(), *value) != when.values.end()) return "";
        std::string values;
        for (size_t k = 0; k < when.values.size(); ++k)
            values += (k == 0 ? "" : k + 1 == when.values.size() ? " or " : ", ") + q(when.values[k]);
        return q(text) + " is filled only when " + q(producerId) + "'s " + when.param + " is " + values + "; it is " +
               q(*value) + " (" + passPath(j) + ".params." + when.param + ")";
    }

    // ' (e.g. "gbuffer.depth")': earlier enabled outputs of the right kind.
    std::string candidates(int before, TextureKind kind) const {
        std::vector<std::string> found;
        for (int j = 0; j < before; ++j) {
            const PassDeclaration* d = decls_[static_cast<size_t>(j)];
            if (!d || !enabled(j)) continue;
            for (const TextureDecl& t : d->outputs)
                if (t.kind == kind) found.push_back(desc_.passes[static_cast<size_t>(j)].id + "." + t.name);
        }
        if (found.empty()) return {};
        std::string s = " (e.g. ";
        for (size_t k = 0; k < found.size() && k < 3; ++k) s += (k ? ", " : "") + q(found[k]);
        return s + ")";
    }

    std::string missingOutput(int j, const std::string& name) const {
        const PassDeclaration& d = *decls_[static_cast<size_t>(j)];
        const std::string& id = desc_.passes[static_cast<size_t>(j)].id;
        for (const TextureDecl& t : d.internals)
            if (t.name == name)
                return q(id + "." + name) + " is internal to " + q(id) + " and cannot be bound";
        std::vector<std::string> names;
        for (const TextureDecl& t : d.outputs) names.push_back(t.name);
        return "pass " + q(id) + " (module " + desc_.passes[static_cast<size_t>(j)].module + ") has no output " +
               q(name) + suggestion(name, names, "outputs");
    }

    // Stage 2c: the graph output: an existing, enabled, colour 2D output.
    void bindOutput() {
        const std::string& text = desc_.output;
        if (text.empty()) {
            error(kOutputKey, "output",
                  "missing graph output: name the texture to show, e.g. \"output\": \"composite.color\"");
            return;
        }
        std::string id, name;
        if (!splitBinding(text, id, name)) {
            error(kOutputKey, "output", "malformed graph output " + q(text) + ": expected \"<pass id>.<output>\"");
            return;
        }
        const int j = lookupPass(id, kOutputKey, "output");
        if (j < 0) return;
        const PassDeclaration* d = decls_[static_cast<size_t>(j)];
        if (!d) return;
        auto out = std::find_if(d->outputs.begin(), d->outputs.end(), [&](const TextureDecl& t) { return t.name == name; });
        if (out == d->outputs.end()) {
            error(kOutputKey, "output", missingOutput(j, name));
            return;
        }
        if (out->kind != TextureKind::Color2D) {
            error(kOutputKey, "output",
                  "graph output " + q(text) + " is " + describe(*out) + "; it must be a color 2D texture");
            return;
        }
        if (!enabled(j)) {
            error(kOutputKey, "output",
                  "graph output " + q(text) + " is produced by " + q(id) + " (" + passPath(j) + "), which is disabled");
            return;
        }
        plan_.output = {j, name};
    }

    // Stage 3: a pass runs when something it writes reaches the graph output or a
    // viewed texture. Bindings only point backwards, so one reverse sweep suffices.
    void cull() {
        const size_t n = plan_.passes.size();
        std::vector<bool> live(n, false);
        for (PlannedPass& pp : plan_.passes) pp.outputRead.assign(pp.decl.outputs.size(), false);
        if (plan_.output.valid()) {
            live[static_cast<size_t>(plan_.output.pass)] = true;
            markRead(plan_.output.pass, plan_.output.name);
        }
        for (const std::string& r : opt_.requested) {
            const std::string what = "viewed texture " + q(r);
            std::string id, name;
            if (!splitBinding(r, id, name)) {
                warning(kRequestedKey, "", what + ": expected \"<pass id>.<texture>\"");
                continue;
            }
            auto it = ids_.find(id);
            if (it == ids_.end()) {
                warning(kRequestedKey, "", what + ": no pass " + q(id) + suggestion(id, idList_, "passes"));
                continue;
            }
            const int j = it->second;
            const PlannedPass& pp = plan_.passes[static_cast<size_t>(j)];
            if (!pp.texture(name)) {
                std::vector<std::string> names;
                for (const TextureDecl& t : pp.decl.outputs) names.push_back(t.name);
                for (const TextureDecl& t : pp.decl.internals) names.push_back(t.name);
                warning(kRequestedKey, "", what + ": pass " + q(id) + " has no texture " + q(name) +
                                               suggestion(name, names, "textures"));
                continue;
            }
            if (!enabled(j)) {
                warning(kRequestedKey, "", what + ": pass " + q(id) + " is disabled");
                continue;
            }
            live[static_cast<size_t>(j)] = true;
            plan_.requested.push_back(r);
            markRead(j, name);
        }
        for (size_t i = n; i-- > 0;) {
            if (!live[i] || !enabled(static_cast<int>(i))) continue;
            for (const Binding& b : plan_.passes[i].bindings)
                if (b.bound()) live[static_cast<size_t>(b.producer)] = true;
        }
        const std::string target = plan_.output.valid() ? q(desc_.output) : std::string("the graph output");
        for (size_t i = 0; i < n; ++i) {
            PlannedPass& pp = plan_.passes[i];
            if (!enabled(static_cast<int>(i))) {
                pp.state = PassState::Disabled;
                pp.reason = "\"enabled\": false";
            } else if (!live[i]) {
                pp.state = PassState::Culled;
                pp.reason = "output not read by " + target + " or any viewed texture";
            } else {
                pp.state = PassState::Run;
            }
        }
        for (const PlannedPass& pp : plan_.passes)
            if (pp.runs())
                for (const Binding& b : pp.bindings)
                    if (b.bound()) markRead(b.producer, b.output);
    }

    // Output `name` of pass j is read (an internal texture's name: nothing to mark).
    void markRead(int j, const std::string& name) {
        PlannedPass& pp = plan_.passes[static_cast<size_t>(j)];
        if (const int k = pp.outputIndex(name); k >= 0) pp.outputRead[static_cast<size_t>(k)] = true;
    }

    // Stage 4: signatures. Producers are named by id, so a change upstream does not
    // change this pass's textures (the host's versions take care of re-running it).
    void sign() {
        for (PlannedPass& pp : plan_.passes) {
            std::string s = "module=" + pp.module + ";params=";
            for (const NamedParam& p : pp.params.values) s += p.name + "=" + formatParamValue(p.value) + ",";
            s += ";inputs=";
            for (const Binding& b : pp.bindings) {
                s += b.slot + "<-";
                s += b.bound() ? plan_.passes[static_cast<size_t>(b.producer)].id + "." + b.output
                               : std::string("fallback:") + toString(b.fallback);
                s += ",";
            }
            s += ";textures=";
            for (const TextureDecl& t : pp.decl.outputs) s += textureKey(t) + ",";
            for (const TextureDecl& t : pp.decl.internals) s += "internal:" + textureKey(t) + ",";
            pp.signature = std::move(s);
            pp.signatureHash = fnv1a(pp.signature);
        }
    }

    const PipelineDesc& desc_;
    const CompileOptions& opt_;
    Plan plan_;
    std::vector<std::pair<int, Diagnostic>> diags_;  // sort key (pass index), diagnostic
    std::map<std::string, int> ids_;                 // pass id → first index
    std::vector<std::string> idList_;                // for suggestions, in file order
    std::map<std::string, Resolved> modules_;        // one resolver call per module
    std::vector<const PassDeclaration*> decls_;      // per pass; null when unresolved
};

}  // namespace

std::optional<ParamValue> checkParamValue(const ParamValue& v, const ParamDecl& d, std::string& problem) {
    return Compiler::checkValue(ParamLiteral::of(v), d, problem);
}

std::optional<ParamValue> checkParamLiteral(const ParamLiteral& l, const ParamDecl& d, std::string& problem) {
    return Compiler::checkValue(l, d, problem);
}

Result<Plan> compile(const PipelineDesc& desc, const CompileOptions& options) {
    return Compiler(desc, options).run();
}

Result<Plan> compileText(const std::string& text, const std::string& fileName, const CompileOptions& options) {
    Result<PipelineDesc> desc = parsePipeline(text, fileName);
    if (!desc) return Result<Plan>(desc.errors());
    Result<PipelineDesc> resolved = resolveExtends(std::move(*desc), readPipelineFile, nullptr, options.pipelineSearchDirs);
    if (!resolved) return Result<Plan>(resolved.errors());
    return compile(*resolved, options);
}

}  // namespace kiln::graph
