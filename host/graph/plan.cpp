// Plan queries and printing (table, graphviz), texture sizes, plan diffs.
#include "graph/plan.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>

namespace kiln::graph {

// ---- params ----------------------------------------------------------------------

const ParamValue* ResolvedParams::find(std::string_view name) const {
    for (const NamedParam& p : values)
        if (p.name == name) return &p.value;
    return nullptr;
}

ParamValue* ResolvedParams::find(std::string_view name) {
    for (NamedParam& p : values)
        if (p.name == name) return &p.value;
    return nullptr;
}

namespace {

// Shortest decimal that reads back as the same float, always with a '.' or exponent
// so it reads as a float in JSON too.
std::string formatFloat(float f) {
    if (!std::isfinite(f)) return std::isnan(f) ? "nan" : (f > 0 ? "inf" : "-inf");
    char buf[32];
    for (int precision = 6; precision <= 9; ++precision) {
        std::snprintf(buf, sizeof buf, "%.*g", precision, static_cast<double>(f));
        if (std::strtof(buf, nullptr) == f) break;
    }
    std::string s = buf;
    if (s.find_first_of(".e") == std::string::npos) s += ".0";
    return s;
}

std::string quoted(const std::string& s) {
    std::string out = "\"";
    for (char c : s) {
        if (c == '"' || c == '\\') out += '\\';
        out += c;
    }
    return out + "\"";
}

// Display width of UTF-8 text (code points; the table uses ←, ², ³).
size_t displayWidth(const std::string& s) {
    size_t n = 0;
    for (unsigned char c : s)
        if ((c & 0xC0) != 0x80) ++n;
    return n;
}

std::string pad(const std::string& s, size_t width) {
    const size_t w = displayWidth(s);
    return w >= width ? s : s + std::string(width - w, ' ');
}

}  // namespace

std::string formatParamValue(const ParamValue& v) {
    if (const bool* b = std::get_if<bool>(&v)) return *b ? "true" : "false";
    if (const int* i = std::get_if<int>(&v)) return std::to_string(*i);
    if (const float* f = std::get_if<float>(&v)) return formatFloat(*f);
    if (const std::string* s = std::get_if<std::string>(&v)) return quoted(*s);
    const Color3& c = std::get<Color3>(v);
    return "[" + formatFloat(c[0]) + ", " + formatFloat(c[1]) + ", " + formatFloat(c[2]) + "]";
}

// ---- passes and plans ------------------------------------------------------------

const char* toString(PassState s) {
    switch (s) {
        case PassState::Run: return "run";
        case PassState::Culled: return "culled";
        case PassState::Disabled: return "disabled";
    }
    return "?";
}

const Binding* PlannedPass::binding(std::string_view slot) const {
    for (const Binding& b : bindings)
        if (b.slot == slot) return &b;
    return nullptr;
}

const TextureDecl* PlannedPass::output(std::string_view name) const {
    const int k = outputIndex(name);
    return k < 0 ? nullptr : &decl.outputs[size_t(k)];
}

int PlannedPass::outputIndex(std::string_view name) const {
    for (size_t k = 0; k < decl.outputs.size(); ++k)
        if (decl.outputs[k].name == name) return int(k);
    return -1;
}

bool PlannedPass::outputIsRead(std::string_view name) const {
    const int k = outputIndex(name);
    return k >= 0 && size_t(k) < outputRead.size() && outputRead[size_t(k)];
}

const TextureDecl* PlannedPass::texture(std::string_view name) const {
    if (const TextureDecl* t = output(name)) return t;
    for (const TextureDecl& t : decl.internals)
        if (t.name == name) return &t;
    return nullptr;
}

int Plan::find(std::string_view id) const {
    for (size_t i = 0; i < passes.size(); ++i)
        if (passes[i].id == id) return static_cast<int>(i);
    return -1;
}

std::vector<int> Plan::runOrder() const {
    std::vector<int> order;
    for (size_t i = 0; i < passes.size(); ++i)
        if (passes[i].runs()) order.push_back(static_cast<int>(i));
    return order;
}

// ---- sizes -----------------------------------------------------------------------

Extent resolveSize(const TextureDecl& t, int outW, int outH, const ResolvedParams& params, const Extent* input,
                   const GridShape& grid) {
    const bool is3D = t.kind == TextureKind::Color3D;
    Extent e;
    switch (t.size.mode) {
        case SizeRule::Mode::RelativeToOutput: {
            auto side = [&](int out) {
                const long v = std::lround(static_cast<double>(t.size.scale) * out);
                return static_cast<int>(std::clamp<long>(v, 1, 1L << 30));
            };
            e.w = side(outW);
            e.h = side(outH);
            break;
        }
        case SizeRule::Mode::Fixed:
            e.w = std::max(1, t.size.width);
            e.h = std::max(1, t.size.height);
            e.d = is3D ? std::max(1, t.size.depth) : 1;
            break;
        case SizeRule::Mode::FromParam: {
            const int* side = params.get<int>(t.size.source);
            const int s = side ? std::max(1, int(std::lround(*side * double(t.size.scale)))) : 1;
            auto along = [&](int axis) { return is3D ? std::max(1, s >> std::clamp(grid.shift[axis], 0, 30)) : s; };
            e.w = along(0) * std::max(1, t.size.tiles);
            e.h = along(1);
            e.d = is3D ? along(2) : 1;
            break;
        }
        case SizeRule::Mode::RelativeOverParam: {
            const int* divisor = params.get<int>(t.size.source);
            const int* cap = t.size.capSource.empty() ? nullptr : params.get<int>(t.size.capSource);
            const double scale = double(t.size.scale) / sizeDivisor(divisor ? *divisor : 1, cap ? *cap : 0, outW, outH);
            auto side = [&](int out) { return static_cast<int>(std::clamp<long>(std::lround(scale * out), 1, 1L << 30)); };
            e.w = side(outW);
            e.h = side(outH);
            break;
        }
        case SizeRule::Mode::FromInput: {
            if (!input) break;  // unbound optional input: its fallback is 1×1(×1)
            auto side = [&](int v) { return std::max(1, int(std::lround(v * double(t.size.scale)))); };
            e.w = side(input->w) * std::max(1, t.size.tiles);
            e.h = side(input->h);
            e.d = is3D ? side(input->d) : 1;
            break;
        }
    }
    return e;
}

Extent Plan::extentOf(int pass, std::string_view name, int outW, int outH, const GridShape& grid) const {
    if (pass < 0 || pass >= static_cast<int>(passes.size())) return {};
    const PlannedPass& p = passes[static_cast<size_t>(pass)];
    const TextureDecl* t = p.texture(name);
    if (!t) return {};
    if (t->size.mode != SizeRule::Mode::FromInput) return resolveSize(*t, outW, outH, p.params, nullptr, grid);
    // Producers come earlier in file order, so this recursion ends.
    const Binding* b = p.binding(t->size.source);
    if (!b || !b->bound() || b->producer >= pass) return resolveSize(*t, outW, outH, p.params, nullptr, grid);
    const Extent in = extentOf(b->producer, b->output, outW, outH, grid);
    return resolveSize(*t, outW, outH, p.params, &in, grid);
}

std::string describeSize(const TextureDecl& t, const ResolvedParams& params) {
    const bool is3D = t.kind == TextureKind::Color3D;
    switch (t.size.mode) {
        case SizeRule::Mode::RelativeToOutput: {
            char buf[32];
            std::snprintf(buf, sizeof buf, "%gx", static_cast<double>(t.size.scale));
            return buf;
        }
        case SizeRule::Mode::Fixed: {
            std::string s = std::to_string(t.size.width) + "x" + std::to_string(t.size.height);
            if (is3D) s += "x" + std::to_string(t.size.depth);
            return s;
        }
        case SizeRule::Mode::FromInput: {
            std::string d = "as input " + t.size.source;
            if (t.size.scale != 1.0f) d = std::to_string(t.size.scale).substr(0, 4) + "× " + d;
            if (t.size.tiles > 1) d += " ×" + std::to_string(t.size.tiles) + " tiles";
            return d;
        }
        case SizeRule::Mode::RelativeOverParam: {
            const int* divisor = params.get<int>(t.size.source);
            char buf[160];
            std::snprintf(buf, sizeof buf, "%gx / %s (%d)", static_cast<double>(t.size.scale), t.size.source.c_str(),
                          divisor ? *divisor : 1);
            std::string d = buf;
            if (const int* cap = t.size.capSource.empty() ? nullptr : params.get<int>(t.size.capSource); cap && *cap > 0)
                d += ", at most " + std::to_string(*cap) + " across (" + t.size.capSource + ")";
            return d;
        }
        case SizeRule::Mode::FromParam: {
            const int* side = params.get<int>(t.size.source);
            std::string d = (side ? std::to_string(*side) : std::string("?")) + (is3D ? "³" : "²") + " (" + t.size.source + ")";
            if (t.size.scale != 1.0f) d = std::to_string(t.size.scale).substr(0, 4) + "×" + d;
            if (t.size.tiles > 1) d += " ×" + std::to_string(t.size.tiles) + " tiles";
            return d;
        }
    }
    return "?";
}

// ---- printing ----------------------------------------------------------------------

namespace {

// One pass's row of the table: column → lines (several inputs or outputs take a line each).
std::vector<std::vector<std::string>> tableRow(const std::vector<PlannedPass>& passes, size_t i) {
    const PlannedPass& p = passes[i];
    std::string state = toString(p.state);
    if (!p.reason.empty()) state += ": " + p.reason;
    std::vector<std::string> inputs, outputs;
    for (const Binding& b : p.bindings) {
        if (b.bound()) {
            inputs.push_back(b.slot + "←" + passes[static_cast<size_t>(b.producer)].id + "." + b.output);
        } else {
            std::string s = b.slot + "←fallback:" + toString(b.fallback);
            if (!b.lost.empty()) s += " (" + b.lost + " disabled)";
            inputs.push_back(s);
        }
    }
    for (size_t k = 0; k < p.decl.outputs.size(); ++k) {
        const TextureDecl& t = p.decl.outputs[k];
        const bool unread = p.runs() && k < p.outputRead.size() && !p.outputRead[k];
        outputs.push_back(t.name + " " + toString(t.format) + " " + describeSize(t, p.params) +
                          (unread ? " unread" : ""));
    }
    for (const TextureDecl& t : p.decl.internals)
        outputs.push_back(t.name + " " + toString(t.format) + " " + describeSize(t, p.params) + " internal");
    if (inputs.empty()) inputs.push_back("-");
    if (outputs.empty()) outputs.push_back("-");
    return {{std::to_string(i)}, {p.id}, {p.module}, {state}, inputs, outputs};
}

}  // namespace

std::string Plan::table() const {
    std::vector<std::vector<std::vector<std::string>>> rows;  // pass → column → lines
    const std::vector<std::string> header = {"#", "id", "module", "state", "inputs", "outputs"};
    for (size_t i = 0; i < passes.size(); ++i) rows.push_back(tableRow(passes, i));

    std::vector<size_t> width(header.size());
    for (size_t c = 0; c < header.size(); ++c) width[c] = displayWidth(header[c]);
    for (const auto& row : rows)
        for (size_t c = 0; c < row.size(); ++c)
            for (const std::string& line : row[c]) width[c] = std::max(width[c], displayWidth(line));

    auto emit = [&](const std::vector<std::string>& cells) {
        std::string line;
        for (size_t c = 0; c < cells.size(); ++c) {
            line += c + 1 == cells.size() ? cells[c] : pad(cells[c], width[c]) + "  ";
        }
        while (!line.empty() && line.back() == ' ') line.pop_back();
        return line + "\n";
    };

    std::string out = emit(header);
    std::vector<std::string> rule;
    for (size_t w : width) rule.push_back(std::string(w, '-'));
    out += emit(rule);
    for (const auto& row : rows) {
        size_t lines = 0;
        for (const auto& col : row) lines = std::max(lines, col.size());
        for (size_t l = 0; l < lines; ++l) {
            std::vector<std::string> cells;
            for (const auto& col : row) cells.push_back(l < col.size() ? col[l] : "");
            out += emit(cells);
        }
    }
    if (output.valid()) out += "output: " + passes[static_cast<size_t>(output.pass)].id + "." + output.name + "\n";
    if (!requested.empty()) {
        out += "viewed:";
        for (const std::string& r : requested) out += " " + r;
        out += "\n";
    }
    return out;
}

std::string Plan::dot() const {
    auto node = [](size_t i) { return "p" + std::to_string(i); };
    std::string out = "digraph pipeline {\n";
    out += "  label=" + quoted(fileName) + ";\n  labelloc=t;\n  rankdir=LR;\n";
    out += "  node [shape=box, style=\"rounded\", fontname=\"Helvetica\"];\n";
    out += "  edge [fontname=\"Helvetica\", fontsize=10];\n";
    for (size_t i = 0; i < passes.size(); ++i) {
        const PlannedPass& p = passes[i];
        std::string label = p.id;
        if (p.module != p.id) label += "\\n(" + p.module + ")";
        std::string attrs;
        if (p.state == PassState::Culled) {
            label += "\\nculled";
            attrs = ", style=\"rounded,filled\", fillcolor=\"grey90\", color=\"grey60\", fontcolor=\"grey50\"";
        } else if (p.state == PassState::Disabled) {
            label += "\\ndisabled";
            attrs = ", style=\"rounded,dashed\", color=\"grey50\", fontcolor=\"grey50\"";
        }
        // The label is built from ids/modules ([a-z0-9_]) and our own "\n"s; quote
        // anything else defensively.
        std::string escaped;
        for (char c : label) {
            if (c == '"') escaped += '\\';
            escaped += c;
        }
        out += "  " + node(i) + " [label=\"" + escaped + "\"" + attrs + "];\n";
    }
    if (output.valid()) out += "  output [shape=oval, label=\"output\"];\n";
    for (size_t i = 0; i < passes.size(); ++i) {
        for (const Binding& b : passes[i].bindings) {
            if (b.bound()) {
                std::string attrs = "label=" + quoted(b.slot) + ", tooltip=" +
                                    quoted(passes[static_cast<size_t>(b.producer)].id + "." + b.output);
                if (passes[i].state != PassState::Run) attrs += ", color=\"grey60\", fontcolor=\"grey50\"";
                out += "  " + node(static_cast<size_t>(b.producer)) + " -> " + node(i) + " [" + attrs + "];\n";
            } else if (!b.lost.empty()) {
                // The binding named a disabled pass: draw it dashed, to the fallback.
                const int from = find(b.lost.substr(0, b.lost.find('.')));
                if (from >= 0)
                    out += "  " + node(static_cast<size_t>(from)) + " -> " + node(i) + " [label=" +
                           quoted(b.slot + " (fallback: " + toString(b.fallback) + ")") +
                           ", style=dashed, color=\"grey50\"];\n";
            }
        }
    }
    if (output.valid())
        out += "  " + node(static_cast<size_t>(output.pass)) + " -> output [label=" + quoted(output.name) + "];\n";
    out += "}\n";
    return out;
}

// ---- diffs -------------------------------------------------------------------------

bool PlanDiff::isUnchanged(std::string_view id) const {
    return std::find(unchanged.begin(), unchanged.end(), id) != unchanged.end();
}

PlanDiff diffPlans(const Plan& before, const Plan& after) {
    PlanDiff d;
    std::map<std::string, const PlannedPass*, std::less<>> old;
    for (const PlannedPass& p : before.passes) old.emplace(p.id, &p);
    for (const PlannedPass& p : after.passes) {
        auto it = old.find(p.id);
        if (it == old.end()) {
            d.added.push_back(p.id);
        } else {
            (it->second->signature == p.signature ? d.unchanged : d.changed).push_back(p.id);
            old.erase(it);
        }
    }
    for (const PlannedPass& p : before.passes)
        if (old.count(p.id)) d.removed.push_back(p.id);
    return d;
}

}  // namespace kiln::graph
