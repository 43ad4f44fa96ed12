// What the benchmark commands share: PASS.PARAM=VALUE overrides applied to a
// pipeline's JSON, medians, reading a file.
#pragma once

#include <algorithm>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace kiln::bench {

struct Override {
    std::string pass, param, json;
};

inline double median(std::vector<double> v) {
    if (v.empty()) return -1.0;
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
}

inline bool parseOverride(const std::string& text, Override& out, std::string& error) {
    auto dot = text.find('.'), eq = text.find('=');
    if (dot == std::string::npos || eq == std::string::npos || dot > eq) {
        error = "\"" + text + "\": expected PASS.PARAM=VALUE";
        return false;
    }
    out = {text.substr(0, dot), text.substr(dot + 1, eq - dot - 1), text.substr(eq + 1)};
    return true;
}

// Applies overrides to the pipeline's JSON text (the graph compiler validates them).
inline bool applyOverrides(const std::string& text, const std::vector<Override>& overrides, std::string& out,
                    std::string& error) {
    nlohmann::json root = nlohmann::json::parse(text, nullptr, false);
    if (root.is_discarded()) {
        error = "pipeline is not valid JSON";
        return false;
    }
    for (auto& o : overrides) {
        bool found = false;
        for (auto& pass : root["passes"])
            if (pass.value("id", "") == o.pass) {
                nlohmann::json value = nlohmann::json::parse(o.json, nullptr, false);
                if (value.is_discarded()) value = o.json;  // a bare word: an enum choice
                pass["params"][o.param] = value;
                found = true;
            }
        if (!found) {
            error = "no pass \"" + o.pass + "\" in the pipeline";
            return false;
        }
    }
    out = root.dump(2);
    return true;
}

inline std::string slurp(const std::string& path) {
    std::ifstream in(path);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

}  // namespace kiln::bench
