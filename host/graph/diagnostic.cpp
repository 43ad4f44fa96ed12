#include "graph/diagnostic.hpp"

namespace kiln::graph {

std::string Diagnostic::str() const {
    std::string s = file;
    if (line > 0) {
        s += ":" + std::to_string(line) + ":" + std::to_string(column);
    }
    if (!s.empty()) s += ": ";
    if (!path.empty()) s += path + ": ";
    if (severity == Severity::Warning) s += "warning: ";
    return s + message;
}

std::string toString(const std::vector<Diagnostic>& ds) {
    std::string s;
    for (const Diagnostic& d : ds) s += d.str() + "\n";
    return s;
}

}  // namespace kiln::graph
