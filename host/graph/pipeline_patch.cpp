// Writing edited values back into a pipeline file's own text: only the edited values
// change, key order, layout and notes stay (patchPipelineText in graph/pipeline.hpp).
// A small scanner finds each value's bytes in text that is known to be valid JSON.
#include "graph/pipeline.hpp"
#include "graph/pipeline_json.hpp"
#include "graph/plan.hpp"  // formatParamValue
#include "kiln/names.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <stdexcept>

namespace kiln::graph {

namespace {

// Byte spans of the values in a JSON text that is known to be valid (it parsed, nesting
// within kMaxNesting). Only what patching needs: each value's [begin, end), and for an
// object member its key (decoded), where its key starts and ends, and where the
// whitespace before the key starts (just after the preceding '{' or ',').
struct JsonSpan {
    struct Member;
    char kind = 0;  // '{', '[', '"', '0' (number), 'l' (true/false/null)
    size_t begin = 0, end = 0;
    std::vector<Member> members;  // '{'
    std::vector<JsonSpan> items;  // '['

    const Member* member(const std::string& key) const;
};

struct JsonSpan::Member {
    std::string key;
    size_t leadBegin = 0;  // [leadBegin, keyBegin): whitespace before the key
    size_t keyBegin = 0, keyEnd = 0;
    JsonSpan value;
};

// The last member with this key (nlohmann keeps the last of duplicates; the parser
// refuses them anyway).
const JsonSpan::Member* JsonSpan::member(const std::string& key) const {
    const Member* found = nullptr;
    for (const Member& m : members)
        if (m.key == key) found = &m;
    return found;
}

class SpanScanner {
public:
    explicit SpanScanner(const std::string& text) : t_(text) {}

    // False (with a reason) only if the text is not the valid JSON it should be.
    bool scan(JsonSpan& root, std::string& error) {
        if (t_.compare(0, 3, "\xEF\xBB\xBF") == 0) i_ = 3;  // nlohmann skips a UTF-8 BOM too
        skipSpace();
        if (!value(root, 0)) {
            error = "cannot find the values' positions in the text (at byte " + std::to_string(i_) + ")";
            return false;
        }
        return true;
    }

private:
    void skipSpace() {
        while (i_ < t_.size() && (t_[i_] == ' ' || t_[i_] == '\t' || t_[i_] == '\n' || t_[i_] == '\r')) ++i_;
    }

    bool take(char c) {
        if (i_ >= t_.size() || t_[i_] != c) return false;
        ++i_;
        return true;
    }

    // At the opening quote; leaves i_ after the closing one.
    bool string() {
        if (!take('"')) return false;
        while (i_ < t_.size()) {
            const char c = t_[i_];
            if (c == '\\') {
                i_ += 2;
            } else {
                ++i_;
                if (c == '"') return true;
            }
        }
        return false;
    }

    bool value(JsonSpan& v, int depth) {
        if (i_ >= t_.size() || depth > kMaxNesting) return false;
        v.begin = i_;
        const char c = t_[i_];
        if (c == '{') {
            v.kind = '{';
            ++i_;
            skipSpace();
            if (!take('}')) {
                size_t lead = v.begin + 1;
                for (;;) {
                    JsonSpan::Member m;
                    m.leadBegin = lead;
                    skipSpace();
                    m.keyBegin = i_;
                    if (!string()) return false;
                    m.keyEnd = i_;
                    m.key = decodeKey(m.keyBegin, m.keyEnd);
                    skipSpace();
                    if (!take(':')) return false;
                    skipSpace();
                    if (!value(m.value, depth + 1)) return false;
                    v.members.push_back(std::move(m));
                    skipSpace();
                    if (take('}')) break;
                    if (!take(',')) return false;
                    lead = i_;
                }
            }
        } else if (c == '[') {
            v.kind = '[';
            ++i_;
            skipSpace();
            if (!take(']')) {
                for (;;) {
                    skipSpace();
                    v.items.emplace_back();
                    if (!value(v.items.back(), depth + 1)) return false;
                    skipSpace();
                    if (take(']')) break;
                    if (!take(',')) return false;
                }
            }
        } else if (c == '"') {
            v.kind = '"';
            if (!string()) return false;
        } else if (c == '-' || (c >= '0' && c <= '9')) {
            v.kind = '0';
            while (i_ < t_.size() && (std::isdigit(static_cast<unsigned char>(t_[i_])) || t_[i_] == '-' ||
                                      t_[i_] == '+' || t_[i_] == '.' || t_[i_] == 'e' || t_[i_] == 'E'))
                ++i_;
        } else if (c == 't' || c == 'f' || c == 'n') {
            v.kind = 'l';
            while (i_ < t_.size() && std::isalpha(static_cast<unsigned char>(t_[i_]))) ++i_;
        } else {
            return false;
        }
        v.end = i_;
        return true;
    }

    // A key as the parser sees it: "\u0069d" is "id". Without a backslash the bytes
    // between the quotes are the key.
    std::string decodeKey(size_t begin, size_t end) const {
        const std::string raw = t_.substr(begin, end - begin);
        if (raw.find('\\') == std::string::npos) return raw.substr(1, raw.size() - 2);
        const Json j = Json::parse(raw, nullptr, /*allow_exceptions=*/false);
        return j.is_string() ? j.get<std::string>() : std::string();
    }

    const std::string& t_;
    size_t i_ = 0;
};

// Is the value in the file (`file`) already what `edited` says? Same type and value,
// arrays element by element; an int in the file equal to an edited float counts as the
// same (a float parameter takes an int), not the other way round (an int parameter
// refuses 2048.0).
bool sameLiteral(const ParamLiteral& file, const ParamLiteral& edited) {
    using T = ParamLiteral::Type;
    if (file.type == T::Int && edited.type == T::Float) return file.f == edited.f;
    if (file.type != edited.type) return false;
    switch (file.type) {
        case T::Null: return true;
        case T::Bool: return file.b == edited.b;
        case T::Int: return file.i == edited.i;
        case T::Float: return file.f == edited.f;  // NaN never equal: it gets refused when written
        case T::String: return file.s == edited.s;
        case T::Array:
            if (file.items.size() != edited.items.size()) return false;
            for (size_t k = 0; k < file.items.size(); ++k)
                if (!sameLiteral(file.items[k], edited.items[k])) return false;
            return true;
        case T::Object: return file.text == edited.text;
    }
    return false;
}

// A value as writePipeline() writes it, on one line: compact JSON, flat arrays spaced
// like collapseFlatArrays() spaces them. Throws std::runtime_error for what JSON cannot
// hold.
std::string literalText(const ParamLiteral& l) {
    if (l.type == ParamLiteral::Type::Float && !std::isfinite(l.f))
        throw std::runtime_error("the value " + formatParamValue(static_cast<float>(l.f)) + " is not finite");
    if (l.type == ParamLiteral::Type::Array) {
        std::string out = "[";
        for (size_t k = 0; k < l.items.size(); ++k) out += (k ? ", " : "") + literalText(l.items[k]);
        return out + "]";
    }
    try {
        const Json j = toJson(l);
        if (j.is_discarded()) throw std::runtime_error("an object value whose text is not JSON");
        return j.dump();
    } catch (const Json::exception&) {
        throw std::runtime_error("a string in it is not valid UTF-8");
    }
}

std::string keyText(const std::string& key) {
    try {
        return Json(key).dump();
    } catch (const Json::exception&) {
        throw std::runtime_error("the name is not valid UTF-8");
    }
}

struct TextEdit {
    size_t begin, end;  // replaced bytes; begin == end for an insertion
    std::string text;
};

std::string passLabel(size_t i, const PassDesc& p) {
    return indexPath("passes", i) + " (\"" + elide(p.id, 40) + "\")";
}

// The first difference between the two descs that is not a value edit, or "".
std::string structuralDifference(const PipelineDesc& file, const PipelineDesc& edited) {
    auto quoted = [](const std::string& s) { return "\"" + elide(s, 40) + "\""; };
    if (file.schema != edited.schema) return "$schema differs";
    if (file.note != edited.note) return "the pipeline's note differs";
    if (file.output != edited.output)
        return "output differs (" + quoted(file.output) + " in the file, " + quoted(edited.output) + " edited)";
    if (file.passes.size() != edited.passes.size())
        return "the file has " + std::to_string(file.passes.size()) + " passes, the edited pipeline " +
               std::to_string(edited.passes.size());
    for (size_t i = 0; i < file.passes.size(); ++i) {
        const PassDesc& a = file.passes[i];
        const PassDesc& b = edited.passes[i];
        const std::string where = indexPath("passes", i);
        if (a.id != b.id) {
            const int moved = edited.find(a.id);
            return where + " is " + quoted(a.id) + " in the file, " + quoted(b.id) + " edited" +
                   (moved >= 0 ? " (passes reordered)" : "");
        }
        if (a.module != b.module)
            return passLabel(i, a) + ": module differs (" + quoted(a.module) + " in the file, " + quoted(b.module) +
                   " edited)";
        if (a.inputs != b.inputs) return passLabel(i, a) + ": inputs differ";
        if (a.note != b.note) return passLabel(i, a) + ": note differs";
        for (const auto& [name, value] : a.params) {
            bool kept = false;
            for (const auto& e : b.params) kept = kept || e.first == name;
            if (!kept) return passLabel(i, a) + ": parameter " + quoted(name) + " is in the file but not edited";
        }
        for (size_t k = 0; k < b.params.size(); ++k)
            for (size_t m = 0; m < k; ++m)
                if (b.params[m].first == b.params[k].first)
                    return passLabel(i, a) + ": parameter " + quoted(b.params[k].first) + " is named twice";
    }
    return "";
}

// `"key": value` pairs as a one-line object, `{ "a": 1, "b": 2 }`; compact (`{"a":1}`)
// when the surrounding object is written without spaces.
std::string oneLineObject(const std::vector<std::pair<std::string, std::string>>& members, const std::string& colon,
                          bool spaced) {
    std::string out = spaced ? "{ " : "{";
    for (size_t k = 0; k < members.size(); ++k)
        out += (k ? (spaced ? ", " : ",") : "") + members[k].first + colon + members[k].second;
    return out + (spaced ? " }" : "}");
}

// Pass i's parameters: a changed value becomes an edit of its text; a new one goes to
// `added` (key and value as JSON text) for passEdits to place.
bool paramValueEdits(size_t i, const PassDesc& was, const PassDesc& now, const JsonSpan::Member* params,
                     std::vector<TextEdit>& edits, std::vector<std::pair<std::string, std::string>>& added,
                     std::string& error) {
    for (const auto& [name, value] : now.params) {
        const ParamLiteral* before = nullptr;
        for (const auto& p : was.params)
            if (p.first == name) before = &p.second;
        try {
            if (!before) {
                added.emplace_back(keyText(name), literalText(value));
            } else if (!sameLiteral(*before, value)) {
                const JsonSpan::Member* m = params ? params->value.member(name) : nullptr;
                if (!m) {
                    error = passLabel(i, was) + ": cannot find parameter \"" + elide(name, 40) + "\" in the text";
                    return false;
                }
                edits.push_back({m->value.begin, m->value.end, literalText(value)});
            }
        } catch (const std::runtime_error& e) {
            error = passLabel(i, was) + ": parameter \"" + elide(name, 40) + "\": " + e.what();
            return false;
        }
    }
    return true;
}

// The edits that turn pass i of the text from `was` into `now`: its enabled flag, its
// changed parameters' values, its added parameters (after the last one, or a new
// "params" object after "module", spaced like its neighbours). False with `error` when
// the text does not hold what the parser read.
bool passEdits(const std::string& original, size_t i, const PassDesc& was, const PassDesc& now, const JsonSpan& pass,
               std::vector<TextEdit>& edits, std::string& error) {
    const JsonSpan::Member* module = pass.member("module");
    const JsonSpan::Member* enabled = pass.member("enabled");
    const JsonSpan::Member* params = pass.member("params");
    if (!module || (params && params->value.kind != '{')) {
        error = passLabel(i, was) + ": cannot find its keys in the text";
        return false;
    }
    // Spacing of a key added next to `m`: the whitespace before m's key, the bytes
    // between its key and its value.
    auto lead = [&](const JsonSpan::Member& m) {
        return original.substr(m.leadBegin, m.keyBegin - m.leadBegin);
    };
    auto colon = [&](const JsonSpan::Member& m) {
        return original.substr(m.keyEnd, m.value.begin - m.keyEnd);
    };
    std::string afterModule;  // keys added after "module", in writePipeline's order

    if (was.enabled != now.enabled) {
        const std::string value = now.enabled ? "true" : "false";
        if (enabled)
            edits.push_back({enabled->value.begin, enabled->value.end, value});
        else  // only a pass turned off can lack the key
            afterModule += "," + lead(*module) + "\"enabled\"" + colon(*module) + value;
    }

    std::vector<std::pair<std::string, std::string>> added;  // key text, value text
    if (!paramValueEdits(i, was, now, params, edits, added, error)) return false;
    if (!added.empty()) {
        if (!params) {
            afterModule += "," + lead(*module) + "\"params\"" + colon(*module) +
                           oneLineObject(added, colon(*module), !lead(*module).empty());
        } else if (params->value.members.empty()) {
            edits.push_back({params->value.begin, params->value.end,
                             oneLineObject(added, colon(*params), !lead(*params).empty())});
        } else {
            const JsonSpan::Member& last = params->value.members.back();
            std::string text;
            for (const auto& [key, value] : added) text += "," + lead(last) + key + colon(last) + value;
            edits.push_back({last.value.end, last.value.end, std::move(text)});
        }
    }
    if (!afterModule.empty()) edits.push_back({module->value.end, module->value.end, std::move(afterModule)});
    return true;
}

}  // namespace

std::optional<std::string> patchPipelineText(const std::string& original, const PipelineDesc& edited,
                                             std::string& error) {
    error.clear();
    Result<PipelineDesc> parsed = parsePipeline(original, edited.fileName.empty() ? "pipeline" : edited.fileName);
    if (!parsed.ok()) {
        error = "the original text does not parse: " + parsed.errorText();
        return std::nullopt;
    }
    const PipelineDesc& file = parsed.value();
    if (!file.extends.empty()) {
        error = "it extends " + file.extends + ", so its passes are partly that file's (not a value edit of this one)";
        return std::nullopt;
    }
    if (std::string why = structuralDifference(file, edited); !why.empty()) {
        error = why + " (not a value edit)";
        return std::nullopt;
    }

    JsonSpan root;
    if (!SpanScanner(original).scan(root, error)) return std::nullopt;
    const JsonSpan::Member* passesMember = root.kind == '{' ? root.member("passes") : nullptr;
    if (!passesMember || passesMember->value.kind != '[' || passesMember->value.items.size() != file.passes.size()) {
        error = "cannot find the passes in the text";  // the parser and the scanner disagree
        return std::nullopt;
    }

    std::vector<TextEdit> edits;
    try {
        for (size_t i = 0; i < file.passes.size(); ++i)
            if (!passEdits(original, i, file.passes[i], edited.passes[i], passesMember->value.items[i], edits, error))
                return std::nullopt;
    } catch (const std::runtime_error& e) {
        error = e.what();
        return std::nullopt;
    }

    // Apply from the end so earlier offsets stay valid. Spans never overlap: replaced
    // values are disjoint, and an insertion sits at a value's end, which is after (or
    // equal to, for an insertion after a replaced last parameter) every span before it.
    std::stable_sort(edits.begin(), edits.end(),
                     [](const TextEdit& a, const TextEdit& b) { return a.begin > b.begin; });
    std::string out = original;
    for (const TextEdit& e : edits) out.replace(e.begin, e.end - e.begin, e.text);
    return out;
}

}  // namespace kiln::graph
