// kiln-bench-render — per-pass GPU and CPU time of pipelines and parameter sweeps,
// headless. A command, not a test: it prints a table and writes CSV.
//
//   kiln-bench-render [--pipeline FILE]... [--size WxH] [--frames N] [--repeats R]
//                     [--set PASS.PARAM=JSON]... [--sweep PASS.PARAM=V1,V2,...] [--out DIR]
//
// Every pass runs every frame (skipping off) so each frame measures the full cost; the
// first 3 frames (shader compilation, first-touch allocation) are discarded. GPU times
// come from GL timestamp pairs; "frame ms" is wall time per frame with a glFinish,
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
#include "support/bench_support.hpp"

namespace fs = std::filesystem;
using namespace kiln;
using Json = nlohmann::json;
using namespace kiln::bench;

namespace {

struct Config {
    std::string pipeline;
    std::vector<Override> overrides;
    std::string label;
};

struct Args {
    std::vector<std::string> pipelines;
    std::vector<Override> sets;
    std::string sweep;
    int width = 720, height = 720, frames = 20, repeats = 3;
    std::string outDir = "bench-out";
};

[[noreturn]] void usageError(const std::string& message) {
    std::fprintf(stderr, "kiln-bench-render: error: %s\n", message.c_str());
    std::exit(2);
}

Args parseArgs(int argc, char** argv) {
    Args args;
    for (int i = 1; i < argc; ++i) {
        std::string a = argv[i];
        auto next = [&]() -> std::string {
            if (i + 1 >= argc) usageError(a + " needs a value");
            return argv[++i];
        };
        if (a == "--pipeline") args.pipelines.push_back(next());
        else if (a == "--size") {
            std::string v = next();
            if (std::sscanf(v.c_str(), "%dx%d", &args.width, &args.height) != 2 || args.width < 1 || args.height < 1)
                usageError("--size " + v + ": expected WxH");
        } else if (a == "--frames") args.frames = std::max(1, std::atoi(next().c_str()));
        else if (a == "--repeats") args.repeats = std::max(1, std::atoi(next().c_str()));
        else if (a == "--out") args.outDir = next();
        else if (a == "--sweep") args.sweep = next();
        else if (a == "--set") {
            Override o;
            std::string error;
            if (!parseOverride(next(), o, error)) usageError("--set " + error);
            args.sets.push_back(o);
        } else if (a == "--help" || a == "-h") {
            std::printf("usage: kiln-bench-render [--pipeline FILE]... [--size WxH] [--frames N] [--repeats R]\n"
                        "                         [--set PASS.PARAM=JSON]... [--sweep PASS.PARAM=V1,V2,...] [--out DIR]\n");
            std::exit(0);
        } else {
            usageError("unknown argument \"" + a + "\"");
        }
    }
    if (args.pipelines.empty()) args.pipelines.push_back(std::string(KILN_SOURCE_DIR) + "/pipelines/default.json");
    return args;
}

// One config per pipeline, or per pipeline × sweep value.
std::vector<Config> configsOf(const Args& args) {
    std::vector<Config> configs;
    for (auto& p : args.pipelines) {
        std::string name = fs::path(p).stem().string();
        if (args.sweep.empty()) {
            configs.push_back({p, args.sets, name});
            continue;
        }
        Override base;
        std::string error;
        if (!parseOverride(args.sweep, base, error)) usageError("--sweep " + error);
        std::stringstream values(base.json);
        std::string v;
        while (std::getline(values, v, ',')) {
            Config c{p, args.sets, name + " " + base.pass + "." + base.param + "=" + v};
            c.overrides.push_back({base.pass, base.param, v});
            configs.push_back(c);
        }
    }
    return configs;
}

struct Measured {
    std::vector<std::string> order;                  // pass ids in plan order
    std::map<std::string, std::vector<double>> gpu, cpu;  // per-repeat medians
    std::vector<double> frameMs;
};

// `repeats` fresh runs of `text`: 3 warm-up frames, then `frames` timed ones.
bool measure(const Args& args, const Config& config, const std::string& text, Measured& m, std::string& error) {
    for (int r = 0; r < args.repeats; ++r) {
        app::Options o;
        app::applyDefaults(o);
        o.headless = true;
        o.width = args.width;
        o.height = args.height;
        o.pipeline = config.pipeline;
        app::App app;
        if (!app.init(o, error) || !app.runtime().loadPipelineText(text, config.pipeline, error)) return false;
        app.runtime().alwaysRun = true;
        for (int f = 0; f < 3; ++f) app.frame();
        glFinish();
        app.runtime().resetTimings();  // only the frames after warm-up count
        std::vector<double> walls;
        for (int f = 0; f < args.frames; ++f) {
            auto t0 = std::chrono::steady_clock::now();
            app.frame();
            glFinish();
            walls.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
        }
        app.runtime().collectGpuTimes();
        m.frameMs.push_back(median(walls));
        for (auto& row : app.runtime().stats()) {
            if (r == 0) m.order.push_back(row.id);
            if (row.ranFrames == 0) continue;
            m.gpu[row.id].push_back(row.gpuMedianMs);
            m.cpu[row.id].push_back(row.cpuMedianMs);
        }
    }
    return true;
}

void report(const Config& config, Measured& m, std::ofstream& csv) {
    std::printf("%s\n  %-14s %10s %10s\n", config.label.c_str(), "pass", "gpu ms", "cpu ms");
    double total = 0;
    for (auto& id : m.order) {
        if (!m.gpu.count(id)) continue;
        double g = median(m.gpu[id]), c = median(m.cpu[id]);
        total += g;
        std::printf("  %-14s %10.2f %10.2f\n", id.c_str(), g, c);
        csv << '"' << config.label << "\"," << id << ",," << g << "," << c << "," << median(m.frameMs) << "\n";
    }
    std::printf("  %-14s %10.2f   frame (wall, glFinish) %.2f ms\n\n", "sum", total, median(m.frameMs));
}

}  // namespace

int main(int argc, char** argv) {
    const Args args = parseArgs(argc, argv);
    const std::vector<Config> configs = configsOf(args);
    std::string error;
    auto context = app::HeadlessContext::create(false, error);
    if (!context) {
        std::fprintf(stderr, "kiln-bench-render: error: %s\n", error.c_str());
        return 1;
    }
    log::setMinLevel(log::Level::Warn);
    std::printf("device: %s\nsize %dx%d, %d frames x %d repeats (medians), every pass every frame\n\n",
                context->description().c_str(), args.width, args.height, args.frames, args.repeats);

    fs::create_directories(args.outDir);
    const std::string csvPath = (fs::path(args.outDir) / "render.csv").string();
    std::ofstream csv(csvPath);
    csv << "config,pass,module,gpu_ms,cpu_ms,frame_ms\n";
    for (auto& config : configs) {
        std::string text;
        Measured m;
        if (!applyOverrides(slurp(config.pipeline), config.overrides, text, error) ||
            !measure(args, config, text, m, error)) {
            std::fprintf(stderr, "kiln-bench-render: error: %s: %s\n", config.pipeline.c_str(), error.c_str());
            return 1;
        }
        report(config, m, csv);
    }
    std::printf("wrote %s\n", csvPath.c_str());
    return 0;
}
