// What the benchmark commands share: PASS.PARAM=VALUE overrides applied to a
// pipeline's JSON, medians, reading a file, a frame of a scene moving in real time.
#pragma once

#include <algorithm>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "app/app.hpp"

namespace kiln::bench {

// --steps-per-frame: physics steps of 1/240 s a frame; 8 is the scene in real time at
// 30 fps, and how far things move between frames is what the passes that redo only what
// moved pay for.
inline constexpr int kDefaultStepsPerFrame = 8, kMaxStepsPerFrame = 240;

// One frame `stepsPerFrame` physics steps on (app.frame() takes the last; a paused scene
// takes none).
inline void frameMoving(app::App& app, int stepsPerFrame) {
    for (int k = 1; k < stepsPerFrame && !app.paused; ++k) app.scene().step();
    app.frame();
}

struct Override {
    std::string pass, param, json;
};

inline double median(std::vector<double> v) {
    if (v.empty()) return -1.0;
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
}

inline bool parseOverride(const std::string& text, Override& out, std::string& error) {
    const std::optional<graph::ParamOverride> parsed = graph::parseParamOverride(text);
    if (!parsed) {
        error = "\"" + text + "\": expected PASS.PARAM=VALUE";
        return false;
    }
    out = {parsed->pass, parsed->param, parsed->value};
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
