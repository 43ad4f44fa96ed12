// graph/diagnostic.hpp — errors as values: where (file, JSON path or line:col) and what.
//
// Every stage of the graph compiler (parse, resolve, bind, cull) reports problems as
// Diagnostics and keeps going, so one compile shows every mistake in the file, not
// just the first. A Diagnostic prints the way a compiler's message does:
//
//     pipelines/x.json: passes[3].inputs.shadow_map: no pass "shadw" (did you mean "shadow"?)
//     pipelines/x.json:12:5: syntax error while parsing object - unexpected '}'
//
// Result<T> carries either a value or the list of errors that prevented it.
#pragma once

#include <cassert>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace kiln::graph {

struct Diagnostic {
    enum class Severity : unsigned char { Error, Warning };

    Severity severity = Severity::Error;
    std::string file;     // "pipelines/default.json"; may be empty for in-memory pipelines
    std::string path;     // JSON path, "passes[3].inputs.shadow_map"; empty = the whole file
    int line = 0;         // 1-based; set only for JSON syntax errors (path is empty then)
    int column = 0;
    std::string message;

    bool isError() const { return severity == Severity::Error; }
    // "file: path: message", "file:line:col: message"; warnings say "warning: ".
    std::string str() const;
};

// Prints one diagnostic per line.
std::string toString(const std::vector<Diagnostic>&);

// A value or the errors that prevented it. Never both, never neither.
template <class T>
class Result {
public:
    Result(T value) : value_(std::move(value)) {}  // NOLINT: implicit on purpose
    Result(Diagnostic error) { errors_.push_back(std::move(error)); }  // NOLINT
    Result(std::vector<Diagnostic> errors) : errors_(std::move(errors)) { assert(!errors_.empty()); }  // NOLINT

    // For a module resolver: `return Result<PassDeclaration>::failure("dlopen: ...")`.
    static Result failure(std::string message) {
        Diagnostic d;
        d.message = std::move(message);
        return Result(std::move(d));
    }

    bool ok() const { return value_.has_value(); }
    explicit operator bool() const { return ok(); }

    T& value() { assert(ok()); return *value_; }
    const T& value() const { assert(ok()); return *value_; }
    T* operator->() { return &value(); }
    const T* operator->() const { return &value(); }
    T& operator*() { return value(); }
    const T& operator*() const { return value(); }

    const std::vector<Diagnostic>& errors() const { return errors_; }
    // All errors, one per line (empty when ok()).
    std::string errorText() const { return toString(errors_); }

private:
    std::optional<T> value_;
    std::vector<Diagnostic> errors_;
};

}  // namespace kiln::graph
