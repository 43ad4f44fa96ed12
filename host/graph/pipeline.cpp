// Reading and writing pipeline files (patching one in place is pipeline_patch.cpp).
// Only the graph's own sources see nlohmann; the public headers stay free of it.
#include "graph/pipeline.hpp"
#include "graph/pipeline_json.hpp"

#include "graph/plan.hpp"  // formatParamValue
#include "kiln/json_text.hpp"
#include "kiln/names.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <optional>
#include <set>
#include <stdexcept>

namespace kiln::graph {


const char* toString(ParamLiteral::Type t) {
    switch (t) {
        case ParamLiteral::Type::Null: return "null";
        case ParamLiteral::Type::Bool: return "bool";
        case ParamLiteral::Type::Int: return "int";
        case ParamLiteral::Type::Float: return "float";
        case ParamLiteral::Type::String: return "string";
        case ParamLiteral::Type::Array: return "array";
        case ParamLiteral::Type::Object: return "object";
    }
    return "?";
}

int PipelineDesc::find(const std::string& id) const {
    for (size_t i = 0; i < passes.size(); ++i)
        if (passes[i].id == id) return static_cast<int>(i);
    return -1;
}

namespace {

const char* jsonTypeName(const Json& j) {
    switch (j.type()) {
        case Json::value_t::null: return "null";
        case Json::value_t::boolean: return "bool";
        case Json::value_t::number_integer:
        case Json::value_t::number_unsigned: return "int";
        case Json::value_t::number_float: return "float";
        case Json::value_t::string: return "string";
        case Json::value_t::array: return "array";
        case Json::value_t::object: return "object";
        default: return "value";
    }
}

ParamLiteral toLiteral(const Json& j) {
    ParamLiteral l;
    l.text = j.dump();
    switch (j.type()) {
        case Json::value_t::boolean:
            l.type = ParamLiteral::Type::Bool;
            l.b = j.get<bool>();
            break;
        case Json::value_t::number_integer:
            l.type = ParamLiteral::Type::Int;
            l.i = j.get<int64_t>();
            l.f = static_cast<double>(l.i);
            break;
        case Json::value_t::number_unsigned: {
            const uint64_t u = j.get<uint64_t>();
            l.type = ParamLiteral::Type::Int;
            l.i = u > static_cast<uint64_t>(std::numeric_limits<int64_t>::max())
                      ? std::numeric_limits<int64_t>::max()
                      : static_cast<int64_t>(u);
            l.f = static_cast<double>(u);
            break;
        }
        case Json::value_t::number_float:
            l.type = ParamLiteral::Type::Float;
            l.f = j.get<double>();
            break;
        case Json::value_t::string:
            l.type = ParamLiteral::Type::String;
            l.s = j.get<std::string>();
            break;
        case Json::value_t::array:
            l.type = ParamLiteral::Type::Array;
            for (const Json& e : j) l.items.push_back(toLiteral(e));
            break;
        case Json::value_t::object: l.type = ParamLiteral::Type::Object; break;
        default: l.type = ParamLiteral::Type::Null; break;
    }
    return l;
}

}  // namespace

std::optional<ParamOverride> parseParamOverride(const std::string& text) {
    const size_t dot = text.find('.'), eq = text.find('=');
    if (dot == std::string::npos || eq == std::string::npos || dot > eq || dot == 0 || eq == dot + 1) return std::nullopt;
    return ParamOverride{text, text.substr(0, dot), text.substr(dot + 1, eq - dot - 1), text.substr(eq + 1)};
}

ParamLiteral parseParamLiteral(const std::string& value) {
    const Json j = Json::parse(value, nullptr, /*allow_exceptions=*/false);
    return toLiteral(j.is_discarded() ? Json(value) : j);
}

namespace {

class Reader {
public:
    Reader(const std::string& file, std::vector<Diagnostic>& errors) : file_(file), errors_(errors) {}

    void error(const std::string& path, std::string message) {
        Diagnostic d;
        d.file = file_;
        d.path = path;
        d.message = std::move(message);
        errors_.push_back(std::move(d));
    }

    bool expect(const Json& j, Json::value_t type, const char* typeName, const std::string& path) {
        if (j.type() == type) return true;
        error(path, std::string("expected ") + typeName + ", got " + jsonTypeName(j) + " " + elide(j.dump()));
        return false;
    }

    void unknownKey(const std::string& path, const std::string& key, const std::vector<std::string>& known) {
        error(keyPath(path, key), "unknown key \"" + key + "\"" + suggestion(key, known, "keys"));
    }

    // Whether the entry names its module (only an extending file may leave it out).
    bool readPass(const Json& j, const std::string& path, PassDesc& pass) {
        static const std::vector<std::string> kKeys = {"id", "module", "enabled", "params", "inputs", "note",
                                                       "remove", "before", "after"};
        if (!j.is_object()) {
            error(path, std::string("a pass is an object {\"id\": ..., \"module\": ...}, got ") + jsonTypeName(j));
            return true;
        }
        bool hasId = false, hasModule = false;
        for (auto it = j.begin(); it != j.end(); ++it) {
            const std::string& key = it.key();
            const Json& v = it.value();
            const std::string p = keyPath(path, key);
            if (key == "id") {
                hasId = true;
                if (expect(v, Json::value_t::string, "string", p)) pass.id = v.get<std::string>();
            } else if (key == "module") {
                hasModule = true;
                if (expect(v, Json::value_t::string, "string", p)) pass.module = v.get<std::string>();
            } else if (key == "enabled") {
                if (expect(v, Json::value_t::boolean, "bool", p)) pass.enabled = v.get<bool>(), pass.enabledGiven = true;
            } else if (key == "remove") {
                if (expect(v, Json::value_t::boolean, "bool", p)) pass.remove = v.get<bool>();
            } else if (key == "before" || key == "after") {
                if (expect(v, Json::value_t::string, "string", p)) (key == "before" ? pass.placeBefore : pass.placeAfter) = v.get<std::string>();
            } else if (key == "note") {
                if (expect(v, Json::value_t::string, "string", p)) pass.note = v.get<std::string>();
            } else if (key == "params") {
                if (!expect(v, Json::value_t::object, "object", p)) continue;
                for (auto pi = v.begin(); pi != v.end(); ++pi) pass.params.emplace_back(pi.key(), toLiteral(pi.value()));
            } else if (key == "inputs") {
                if (!expect(v, Json::value_t::object, "object", p)) continue;
                for (auto ii = v.begin(); ii != v.end(); ++ii) {
                    const std::string ip = keyPath(p, ii.key());
                    if (ii.value().is_null()) {  // in an extending file: unbind the base's (resolveExtends)
                        pass.inputs.emplace_back(ii.key(), std::string());
                        continue;
                    }
                    if (!ii.value().is_string()) {
                        error(ip, std::string("an input binding is a string \"<pass id>.<output>\", got ") +
                                      jsonTypeName(ii.value()) + " " + elide(ii.value().dump()));
                        continue;
                    }
                    pass.inputs.emplace_back(ii.key(), ii.value().get<std::string>());
                }
            } else {
                unknownKey(path, key, kKeys);
            }
        }
        if (!hasId) error(path, "missing \"id\" (a name for this pass, [a-z0-9_]+)");
        if (!pass.placeBefore.empty() && !pass.placeAfter.empty())
            error(path, "\"before\" and \"after\" both given: a pass goes in one place");
        return hasModule;
    }

    void readPipeline(const Json& root, PipelineDesc& desc) {
        static const std::vector<std::string> kKeys = {"$schema", "extends", "note", "output", "passes"};
        if (!root.is_object()) {
            error("", std::string("a pipeline file is a JSON object {\"output\": ..., \"passes\": [...]}, got ") +
                          jsonTypeName(root));
            return;
        }
        bool hasPasses = false;
        std::vector<size_t> withoutModule;
        for (auto it = root.begin(); it != root.end(); ++it) {
            const std::string& key = it.key();
            const Json& v = it.value();
            if (key == "$schema") {
                if (expect(v, Json::value_t::string, "string", key)) desc.schema = v.get<std::string>();
            } else if (key == "note") {
                if (expect(v, Json::value_t::string, "string", key)) desc.note = v.get<std::string>();
            } else if (key == "extends") {
                if (expect(v, Json::value_t::string, "string", key)) desc.extends = v.get<std::string>();
            } else if (key == "output") {
                if (expect(v, Json::value_t::string, "string", key)) desc.output = v.get<std::string>();
            } else if (key == "passes") {
                hasPasses = true;
                if (!expect(v, Json::value_t::array, "array", key)) continue;
                desc.passes.resize(v.size());
                for (size_t i = 0; i < v.size(); ++i)
                    if (!readPass(v[i], indexPath("passes", i), desc.passes[i]) && !desc.passes[i].remove)
                        withoutModule.push_back(i);
            } else {
                unknownKey("", key, kKeys);
            }
        }
        // A file that extends another may only change the base's passes, or none.
        if (desc.extends.empty()) {
            for (size_t i : withoutModule)
                error(indexPath("passes", i), "missing \"module\" (the pass module to run, e.g. \"gbuffer\")");
            if (!hasPasses) error("", "missing \"passes\" (the list of passes, in execution order)");
        }
    }

private:
    const std::string& file_;
    std::vector<Diagnostic>& errors_;
};

// nlohmann's what(): "[json.exception.parse_error.101] parse error at line 3, column 5:
// syntax error while parsing ..." — keep only the part after the position.
// Its "last read: '...'" quotes the whole token, which an unterminated string makes
// as long as the file: keep the end of it, where the parser stopped.
std::string syntaxMessage(const std::string& what) {
    std::string message = what;
    if (size_t p = what.find("parse error"); p != std::string::npos)
        if (size_t colon = what.find(": ", p); colon != std::string::npos) message = what.substr(colon + 2);
    const std::string lastRead = "; last read: '";
    if (size_t p = message.find(lastRead); p != std::string::npos) {
        const size_t start = p + lastRead.size(), quoted = message.size() - start - 1;  // up to the closing '
        constexpr size_t kShown = 40;
        if (quoted > kShown) message = message.substr(0, start) + "..." + message.substr(message.size() - 1 - kShown);
    }
    return elide(message, 300);
}


// An error at the first bracket that opens level kMaxNesting + 1, or nothing when the
// text stays within the bound.
std::optional<Diagnostic> tooDeep(const std::string& text, const std::string& fileName) {
    const size_t at = json_text::firstTooDeep(text, kMaxNesting);
    if (at == std::string::npos) return std::nullopt;
    Diagnostic d;
    d.file = fileName;
    lineColumn(text, at, d.line, d.column);
    d.message = "nested deeper than " + std::to_string(kMaxNesting) + " levels";
    return d;
}

// The JSON library's other refusals (a number beyond double range, 406; invalid
// UTF-8, 316): named, located where the message quotes the text.
Diagnostic jsonLimitError(const std::string& text, const std::string& fileName, const Json::exception& e) {
    Diagnostic d;
    d.file = fileName;
    std::string what = e.what();
    const size_t bracket = what.find("] ");
    if (bracket != std::string::npos) what = what.substr(bracket + 2);
    const size_t open = what.find('\''), close = what.rfind('\'');
    if (open != std::string::npos && close > open + 1) {
        const size_t at = text.find(what.substr(open + 1, close - open - 1));
        if (at != std::string::npos) lineColumn(text, at, d.line, d.column);
    }
    if (e.id == 406) what += " (beyond the range of a double)";
    d.message = elide(what, 160);
    return d;
}

// nlohmann reports the *last* byte it read, i.e. the end of the offending token
// ("module" in `"x" "module"`); editors want its start. Scan tokens from the top
// (strings with escapes, bare words/numbers, punctuation) to find the one that holds
// `at`. Returns `at` itself when it is not inside a token.
size_t tokenStart(const std::string& text, size_t at) {
    size_t i = 0;
    while (i < text.size() && i <= at) {
        const char c = text[i];
        size_t end = i + 1;
        if (c == '"') {
            while (end < text.size() && text[end] != '"' && text[end] != '\n') end += text[end] == '\\' ? 2 : 1;
            ++end;  // the closing quote
        } else if (std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '+' || c == '.') {
            while (end < text.size() && (std::isalnum(static_cast<unsigned char>(text[end])) || text[end] == '.' ||
                                         text[end] == '-' || text[end] == '+'))
                ++end;
        } else if (std::isspace(static_cast<unsigned char>(c))) {
            if (at == i) return at;
        }
        if (at >= i && at < end) return i;
        i = end;
    }
    return at;
}

// dump(2) puts every array element on its own line; a colour reads better as
// [1, 0.9, 0.8]. Arrays without nested arrays/objects/strings are put on one line.
std::string collapseFlatArrays(const std::string& text) {
    std::string out;
    out.reserve(text.size());
    size_t i = 0;
    while (i < text.size()) {
        if (text[i] == '"') {  // copy strings verbatim
            size_t end = i + 1;
            while (end < text.size() && text[end] != '"') end += text[end] == '\\' ? 2 : 1;
            out.append(text, i, end + 1 - i);
            i = end + 1;
            continue;
        }
        if (text[i] == '[') {
            const size_t close = text.find_first_of("[]{}\"", i + 1);
            if (close != std::string::npos && text[close] == ']') {
                std::string flat = "[";
                bool space = false;
                for (size_t k = i + 1; k < close; ++k) {
                    if (std::isspace(static_cast<unsigned char>(text[k]))) {
                        space = true;
                        continue;
                    }
                    if (space && flat.back() == ',') flat += ' ';
                    space = false;
                    flat += text[k];
                }
                out += flat + "]";
                i = close + 1;
                continue;
            }
        }
        out += text[i++];
    }
    return out;
}

}  // namespace

Json toJson(const ParamLiteral& l) {
    switch (l.type) {
        case ParamLiteral::Type::Bool: return l.b;
        case ParamLiteral::Type::Int: return l.i;
        case ParamLiteral::Type::Float: return l.f;
        case ParamLiteral::Type::String: return l.s;
        case ParamLiteral::Type::Array: {
            Json a = Json::array();
            for (const ParamLiteral& e : l.items) a.push_back(toJson(e));
            return a;
        }
        case ParamLiteral::Type::Object:
            // Kept as its text: an object is never a valid parameter, but writing back
            // should not lose what the user wrote.
            return Json::parse(l.text.empty() ? std::string("{}") : l.text, nullptr, false);
        case ParamLiteral::Type::Null: break;
    }
    return nullptr;
}

void setParamLiteral(PassDesc& pass, const std::string& name, const ParamValue& value) {
    ParamLiteral literal = ParamLiteral::of(value);
    for (auto& [k, v] : pass.params)
        if (k == name) {
            v = std::move(literal);
            return;
        }
    pass.params.emplace_back(name, std::move(literal));
}

ParamLiteral ParamLiteral::of(const ParamValue& v) {
    Json j;
    if (const bool* b = std::get_if<bool>(&v)) j = *b;
    else if (const int* i = std::get_if<int>(&v)) j = *i;
    // Floats go through their shortest decimal form, so 0.9f is written as 0.9, not
    // as the double 0.89999997615814209.
    else if (const float* f = std::get_if<float>(&v)) j = std::strtod(formatParamValue(*f).c_str(), nullptr);
    else if (const std::string* s = std::get_if<std::string>(&v)) j = *s;
    else if (const Color3* c = std::get_if<Color3>(&v))
        j = Json::array({std::strtod(formatParamValue((*c)[0]).c_str(), nullptr),
                         std::strtod(formatParamValue((*c)[1]).c_str(), nullptr),
                         std::strtod(formatParamValue((*c)[2]).c_str(), nullptr)});
    return toLiteral(j);
}

Result<PipelineDesc> parsePipeline(const std::string& text, const std::string& fileName) {
    std::vector<Diagnostic> errors;
    std::vector<std::string> duplicates;
    Json root;
    if (auto deep = tooDeep(text, fileName)) return Result<PipelineDesc>(std::move(*deep));
    try {
        // nlohmann silently keeps the last of two equal keys; a second "params" block
        // that wins over the first is a nasty surprise, so the tracker notes them.
        json_text::PathTracker tracker;
        root = Json::parse(text, std::ref(tracker), /*allow_exceptions=*/true, /*ignore_comments=*/false);
        duplicates = tracker.duplicateKeys();
    } catch (const Json::parse_error& e) {
        Diagnostic d;
        d.file = fileName;
        // e.byte is 1-based: the last character read, i.e. the offending one.
        const size_t at = tokenStart(text, e.byte > 0 ? e.byte - 1 : 0);
        lineColumn(text, at, d.line, d.column);
        d.message = syntaxMessage(e.what());
        if (at < text.size() && text[at] == '/')
            d.message += " (comments are not JSON: put prose in a \"note\" field)";
        return Result<PipelineDesc>(std::move(d));
    } catch (const Json::exception& e) {
        return Result<PipelineDesc>(jsonLimitError(text, fileName, e));
    }

    PipelineDesc desc;
    desc.fileName = fileName;
    Reader reader(fileName, errors);
    for (const std::string& p : duplicates) reader.error(p, "duplicate key: only the last one would count");
    reader.readPipeline(root, desc);
    if (!errors.empty()) return Result<PipelineDesc>(std::move(errors));
    return Result<PipelineDesc>(std::move(desc));
}

std::string writePipeline(const PipelineDesc& desc) {
    Json root = Json::object();
    if (!desc.schema.empty()) root["$schema"] = desc.schema;
    if (!desc.note.empty()) root["note"] = desc.note;
    root["output"] = desc.output;
    Json passes = Json::array();
    for (const PassDesc& p : desc.passes) {
        Json j = Json::object();
        j["id"] = p.id;
        j["module"] = p.module;
        if (!p.enabled) j["enabled"] = false;
        if (!p.note.empty()) j["note"] = p.note;
        if (!p.params.empty()) {
            Json params = Json::object();
            for (const auto& [name, value] : p.params) params[name] = toJson(value);
            j["params"] = std::move(params);
        }
        if (!p.inputs.empty()) {
            Json inputs = Json::object();
            for (const auto& [slot, binding] : p.inputs) inputs[slot] = binding;
            j["inputs"] = std::move(inputs);
        }
        passes.push_back(std::move(j));
    }
    root["passes"] = std::move(passes);
    return collapseFlatArrays(root.dump(2)) + "\n";
}

}  // namespace kiln::graph
