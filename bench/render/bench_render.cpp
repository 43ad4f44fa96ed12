// kiln-bench-render — per-pass GPU and CPU time of pipelines and parameter sweeps,
// headless. A command, not a test: it prints a table and writes CSV.
//
//   kiln-bench-render [--pipeline FILE]... [--size WxH] [--frames N] [--repeats R]
//                     [--set PASS.PARAM=JSON]... [--sweep PASS.PARAM=V1,V2,...] [--out DIR]
//
// Every pass runs every frame (skipping off) so each frame measures the full cost; the
// first 3 frames (shader compilation, first-touch allocation) are discarded. GPU times
// come from GL_TIME_ELAPSED queries; "frame ms" is wall time per frame with a glFinish,
// which on llvmpipe is what a user waits for.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include <nlohmann/json.hpp>

#include "app/app.hpp"
#include "app/context.hpp"
#include "kiln/log.hpp"

namespace fs = std::filesystem;
using namespace kiln;
using Json = nlohmann::json;

namespace {

struct Override {
    std::string pass, param, json;
};

struct Config {
    std::string pipeline;
    std::vector<Override> overrides;
    std::string label;
};

double median(std::vector<double> v) {
    if (v.empty()) return -1.0;
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
}

bool parseOverride(const std::string& text, Override& out, std::string& error) {
    auto dot = text.find('.'), eq = text.find('=');
    if (dot == std::string::npos || eq == std::string::npos || dot > eq) {
        error = "\"" + text + "\": expected PASS.PARAM=VALUE";
        return false;
    }
    out = {text.substr(0, dot), text.substr(dot + 1, eq - dot - 1), text.substr(eq + 1)};
    return true;
}

// Applies overrides to the pipeline's JSON text (the graph compiler validates them).
bool applyOverrides(const std::string& text, const std::vector<Override>& overrides, std::string& out,
                    std::string& error) {
    Json root = Json::parse(text, nullptr, false);
    if (root.is_discarded()) {
        error = "pipeline is not valid JSON";
        return false;
    }
    for (auto& o : overrides) {
        bool found = false;
        for (auto& pass : root["passes"])
            if (pass.value("id", "") == o.pass) {
                Json value = Json::parse(o.json, nullptr, false);
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

std::string slurp(const std::string& path) {
    std::ifstream in(path);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

}  // namespace

int main(int argc, char** argv) {
    std::vector<std::string> pipelines;
    std::vector<Override> sets;
    std::string sweep;
    int width = 720, height = 720, frames = 20, repeats = 3;
    std::string outDir = "bench-out";
    for (int i = 1; i < argc; ++i) {
        std::string a = argv[i];
        auto next = [&]() -> std::string {
            if (i + 1 >= argc) {
                std::fprintf(stderr, "kiln-bench-render: error: %s needs a value\n", a.c_str());
                std::exit(2);
            }
            return argv[++i];
        };
        if (a == "--pipeline") pipelines.push_back(next());
        else if (a == "--size") {
            std::string v = next();
            if (std::sscanf(v.c_str(), "%dx%d", &width, &height) != 2 || width < 1 || height < 1) {
                std::fprintf(stderr, "kiln-bench-render: error: --size %s: expected WxH\n", v.c_str());
                return 2;
            }
        } else if (a == "--frames") frames = std::max(1, std::atoi(next().c_str()));
        else if (a == "--repeats") repeats = std::max(1, std::atoi(next().c_str()));
        else if (a == "--out") outDir = next();
        else if (a == "--sweep") sweep = next();
        else if (a == "--set") {
            Override o;
            std::string error;
            if (!parseOverride(next(), o, error)) {
                std::fprintf(stderr, "kiln-bench-render: error: --set %s\n", error.c_str());
                return 2;
            }
            sets.push_back(o);
        } else if (a == "--help" || a == "-h") {
            std::printf("usage: kiln-bench-render [--pipeline FILE]... [--size WxH] [--frames N] [--repeats R]\n"
                        "                         [--set PASS.PARAM=JSON]... [--sweep PASS.PARAM=V1,V2,...] [--out DIR]\n");
            return 0;
        } else {
            std::fprintf(stderr, "kiln-bench-render: error: unknown argument \"%s\"\n", a.c_str());
            return 2;
        }
    }
    if (pipelines.empty()) pipelines.push_back(std::string(KILN_SOURCE_DIR) + "/pipelines/default.json");

    std::vector<Config> configs;
    for (auto& p : pipelines) {
        std::string name = fs::path(p).stem().string();
        if (sweep.empty()) {
            configs.push_back({p, sets, name});
            continue;
        }
        Override base;
        std::string error;
        if (!parseOverride(sweep, base, error)) {
            std::fprintf(stderr, "kiln-bench-render: error: --sweep %s\n", error.c_str());
            return 2;
        }
        std::stringstream values(base.json);
        std::string v;
        while (std::getline(values, v, ',')) {
            Config c{p, sets, name + " " + base.pass + "." + base.param + "=" + v};
            c.overrides.push_back({base.pass, base.param, v});
            configs.push_back(c);
        }
    }

    std::string error;
    auto context = app::HeadlessContext::create(false, error);
    if (!context) {
        std::fprintf(stderr, "kiln-bench-render: error: %s\n", error.c_str());
        return 1;
    }
    log::setMinLevel(log::Level::Warn);
    std::printf("device: %s\nsize %dx%d, %d frames x %d repeats (medians), every pass every frame\n\n",
                context->description().c_str(), width, height, frames, repeats);

    fs::create_directories(outDir);
    const std::string csvPath = (fs::path(outDir) / "render.csv").string();
    std::ofstream csv(csvPath);
    csv << "config,pass,module,gpu_ms,cpu_ms,frame_ms\n";

    for (auto& config : configs) {
        std::string text;
        if (!applyOverrides(slurp(config.pipeline), config.overrides, text, error)) {
            std::fprintf(stderr, "kiln-bench-render: error: %s: %s\n", config.pipeline.c_str(), error.c_str());
            return 1;
        }
        std::map<std::string, std::vector<double>> gpu, cpu;
        std::vector<std::string> order;
        std::vector<double> frameMs;
        for (int r = 0; r < repeats; ++r) {
            app::Options o;
            app::applyDefaults(o);
            o.headless = true;
            o.width = width;
            o.height = height;
            o.pipeline = config.pipeline;
            app::App app;
            if (!app.init(o, error) || !app.runtime().loadPipelineText(text, config.pipeline, error)) {
                std::fprintf(stderr, "kiln-bench-render: error: %s\n", error.c_str());
                return 1;
            }
            app.runtime().alwaysRun = true;
            for (int f = 0; f < 3; ++f) app.frame();
            glFinish();
            app.runtime().resetTimings();  // only the frames after warm-up count
            std::vector<double> walls;
            for (int f = 0; f < frames; ++f) {
                auto t0 = std::chrono::steady_clock::now();
                app.frame();
                glFinish();
                walls.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
            }
            app.runtime().collectGpuTimes();
            frameMs.push_back(median(walls));
            for (auto& row : app.runtime().stats()) {
                if (r == 0) order.push_back(row.id);
                if (row.ranFrames == 0) continue;
                gpu[row.id].push_back(row.gpuMedianMs);
                cpu[row.id].push_back(row.cpuMedianMs);
            }
        }
        std::printf("%s\n  %-14s %10s %10s\n", config.label.c_str(), "pass", "gpu ms", "cpu ms");
        double total = 0;
        for (auto& id : order) {
            if (!gpu.count(id)) continue;
            double g = median(gpu[id]), c = median(cpu[id]);
            total += g;
            std::printf("  %-14s %10.2f %10.2f\n", id.c_str(), g, c);
            csv << '"' << config.label << "\"," << id << ",," << g << "," << c << "," << median(frameMs) << "\n";
        }
        std::printf("  %-14s %10.2f   frame (wall, glFinish) %.2f ms\n\n", "sum", total, median(frameMs));
    }
    std::printf("wrote %s\n", csvPath.c_str());
    return 0;
}
