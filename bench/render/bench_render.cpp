// kiln-bench-render — per-pass GPU and CPU time of pipelines and parameter sweeps,
// headless. A command, not a test: it prints a table and writes CSV.
//
//   kiln-bench-render [--pipeline FILE]... [--scene FILE] [--size WxH] [--frames N]
//                     [--repeats R] [--settle SECONDS] [--steps-per-frame N] [--set PASS.PARAM=JSON]...
//                     [--sweep PASS.PARAM=V1,V2,...]... | [--grow fireballs|marbles=N1,N2,...]
//                     [--out DIR]
//
// Each --sweep varies one parameter, the others at the file's (and --set's) values.
// Every pass runs every frame (skipping off) so each frame measures the full cost; the
// scene moves (the simulation steps every frame). The first 3 frames (shader
// compilation, first-touch allocation) are discarded. GPU times come from GL timestamp
// pairs; "frame ms" is wall time per frame with a glFinish, which on llvmpipe is what
// a user waits for. Configurations are measured in rounds: each round visits every
// configuration once (a slow minute of a shared machine lands on all of them alike);
// the figures are medians over frames, then over rounds. Each round also times an
// empty full-screen pass (the floor every screen pass pays); every pass is reported
// as a multiple of it too.
//
// Each configuration first simulates --settle seconds (default 1.5, without
// rendering) so the fire's particles reach their steady count: the first frames of a
// run have almost none.
// --grow: the scene with its fireball (marble) list replaced by N of them on a lattice
// in the upper box, per N.
// Prints frame cost against the body and particle counts and writes growth.csv and
// growth.png besides render.csv.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include <nlohmann/json.hpp>

#include "app/app.hpp"
#include <kiln/plot_script.hpp>
#include "app/context.hpp"
#include "kiln/gl.hpp"
#include "kiln/log.hpp"
#include "command_line/command_line.hpp"
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
    std::string scene;  // empty: the default scene
    int grown = -1;     // --grow: the body count
};

struct Args {
    std::vector<std::string> pipelines;
    std::vector<Override> sets;
    std::vector<std::string> sweeps;  // each swept on its own, the others at the file's values
    std::string scene, growKind;
    std::vector<int> growCounts;
    double settle = 1.5;
    int stepsPerFrame = kDefaultStepsPerFrame;
    int width = 720, height = 720, frames = 20, repeats = 3;
    std::string outDir = "bench-out";
};

[[noreturn]] void usageError(const std::string& message) {
    std::fprintf(stderr, "kiln-bench-render: error: %s (see kiln-bench-render --help)\n", message.c_str());
    std::exit(2);
}

Args parseArgs(int argc, char** argv) {
    Args args;
    CLI::App app{"kiln-bench-render — each pipeline's frame time per pass (GPU timer queries and CPU), with the\n"
                 "scene moving in real time; --sweep measures a knob's values, --grow a scene of more and more\n"
                 "bodies. Writes OUT/render.csv (and the sweep's or growth's CSV and plot).",
                 "kiln-bench-render"};
    cli::configure(app);
    app.add_option("--pipeline", args.pipelines, "a pipeline to time (repeatable; default pipelines/default.json)")
        ->type_name("FILE")->allow_extra_args(false);
    app.add_option("--scene", args.scene, "the scene (default scenes/cornell.json)")->type_name("FILE");
    cli::addSize(app, "--size", args.width, args.height, 1, 16384, "the picture's size (default 720x720)");
    app.add_option("--frames", args.frames, "timed frames per repeat (default 20)")->type_name("N")->check(CLI::Range(1, 1 << 20));
    app.add_option("--repeats", args.repeats, "repeats, the median kept (default 3)")->type_name("N")->check(CLI::Range(1, 1 << 20));
    app.add_option("--settle", args.settle, "simulated seconds before timing (default 1.5)")->type_name("S")->check(CLI::Range(0.0, 60.0));
    app.add_option("--steps-per-frame", args.stepsPerFrame, "physics steps of 1/240 s a frame (default 8: real time at 30 fps)")
        ->type_name("N")->check(CLI::Range(1, kMaxStepsPerFrame));
    std::vector<std::string> sets;
    app.add_option("--set", sets, "a parameter over every pipeline's value (repeatable)")->type_name("PASS.PARAM=JSON")->allow_extra_args(false);
    app.add_option("--sweep", args.sweeps, "a knob's values, each timed on its own (repeatable)")
        ->type_name("PASS.PARAM=V1,V2")->allow_extra_args(false);
    std::string grow;
    app.add_option("--grow", grow, "time the scene with that many fireballs or marbles")->type_name("fireballs|marbles=N1,N2");
    app.add_option("--out", args.outDir, "where the CSV and plots go (default bench-out)")->type_name("DIR");
    if (const std::optional<int> exitNow = cli::parse(app, argc, argv)) std::exit(*exitNow);
    for (const std::string& set : sets) {
        Override o;
        std::string error;
        if (!parseOverride(set, o, error)) usageError("--set " + error);
        args.sets.push_back(o);
    }
    if (!grow.empty()) {
        const size_t eq = grow.find('=');
        args.growKind = grow.substr(0, eq);
        if (eq == std::string::npos || (args.growKind != "fireballs" && args.growKind != "marbles"))
            usageError("--grow " + grow + ": expected fireballs=N1,N2,... or marbles=N1,N2,...");
        std::stringstream counts(grow.substr(eq + 1));
        for (std::string c; std::getline(counts, c, ',');) {
            char* end = nullptr;
            const long n = std::strtol(c.c_str(), &end, 10);
            if (c.empty() || *end || n < 0 || n > 1000) usageError("--grow " + grow + ": counts are integers in [0, 1000]");
            args.growCounts.push_back(int(n));
        }
    }
    // A grown scene is measured at the pipeline's settings (and --set's): a sweep beside
    // it would be ignored, so it is refused.
    if (!args.sweeps.empty() && !args.growKind.empty())
        usageError("--sweep with --grow: grow one setting at a time (--set PASS.PARAM=V), or sweep without --grow");
    if (args.pipelines.empty()) args.pipelines.push_back((app::defaultDataRoot() / "pipelines/default.json").string());
    return args;
}

// The scene file with its `kind` list ("fireballs" or "marbles") replaced by `count`
// bodies like its first one (or a default), on a 5 × 4 × 5 lattice over the upper box
// (x, z in ±0.64, y in [0.0, 0.75]), each with its own deterministic velocity.
std::string grownScene(const std::string& sceneFile, const std::string& kind, int count, const std::string& outDir) {
    // The scene loader checks the rest when the grown file loads; here only what
    // growing needs: a readable JSON object.
    if (!fs::is_regular_file(sceneFile)) usageError("--grow: " + sceneFile + ": cannot read the scene file");
    Json scene;
    try {
        scene = Json::parse(slurp(sceneFile));
    } catch (const Json::exception& e) {
        usageError("--grow: " + sceneFile + ": " + e.what());
    }
    if (!scene.is_object()) usageError("--grow: " + sceneFile + ": not a JSON object");
    Json like = scene.contains(kind) && !scene[kind].empty() ? scene[kind][0] : Json::object();
    if (!like.contains("radius")) like["radius"] = 0.05;
    if (!like.contains("color")) like["color"] = {1.0, 0.5, 0.1};
    Json list = Json::array();
    for (int i = 0; i < count; ++i) {
        const int slot = i % 100, layer = i / 100;
        const double x = -0.64 + 0.32 * (slot % 5), z = -0.64 + 0.32 * ((slot / 5) % 5);
        const double y = 0.0 + 0.25 * (slot / 25) + 0.05 * layer;
        Json b = like;
        b["position"] = {x + (kind == "fireballs" ? 0.08 : 0.0), y, z};
        const double a = 2.399963 * i;  // golden-angle headings, speeds 0.6..1.2
        const double speed = 0.6 + 0.6 * std::fmod(0.618034 * i, 1.0);
        b["velocity"] = {speed * std::cos(a), 0.3 * speed * std::sin(1.7 * a), speed * std::sin(a)};
        list.push_back(b);
    }
    scene[kind] = list;
    fs::create_directories(outDir);
    const std::string path = (fs::path(outDir) / ("scene-" + kind + "-" + std::to_string(count) + ".json")).string();
    std::ofstream(path) << scene.dump(2) << "\n";
    return path;
}

// One config per pipeline, per pipeline × sweep value, or per pipeline × grown scene.
std::vector<Config> configsOf(const Args& args) {
    std::vector<Config> configs;
    for (auto& p : args.pipelines) {
        std::string name = fs::path(p).stem().string();
        if (!args.growKind.empty()) {
            const std::string base = args.scene.empty() ? (app::defaultDataRoot() / "scenes/cornell.json").string() : args.scene;
            for (int n : args.growCounts)
                configs.push_back({p, args.sets, name + " " + std::to_string(n) + " " + args.growKind,
                                   grownScene(base, args.growKind, n, args.outDir), n});
            continue;
        }
        if (args.sweeps.empty()) {
            configs.push_back({p, args.sets, name, args.scene});
            continue;
        }
        for (const std::string& sweep : args.sweeps) {
            Override base;
            std::string error;
            if (!parseOverride(sweep, base, error)) usageError("--sweep " + error);
            std::stringstream values(base.json);
            std::string v;
            while (std::getline(values, v, ',')) {
                Config c{p, args.sets, name + " " + base.pass + "." + base.param + "=" + v, args.scene};
                c.overrides.push_back({base.pass, base.param, v});
                configs.push_back(c);
            }
        }
    }
    return configs;
}

struct Measured {
    std::vector<std::string> order;                  // pass ids in plan order
    std::map<std::string, std::vector<double>> gpu, cpu;  // per-round medians
    std::vector<double> frameMs, particles;
};

// The floor: the time of an empty full-screen pass at the output size (a triangle over an
// RGBA16F target, each pixel's coordinates written: no input, no math), the median of
// `draws` timed draws after 3 warm-up ones. Every screen pass costs at least this; the
// tables report each pass as a multiple of it. 0 when the program does not build.
double emptyPassMs(int width, int height, int draws) {
    static const char* kVertex = R"(#version 450 core
        void main() {
            vec2 p = vec2((gl_VertexID << 1) & 2, gl_VertexID & 2);
            gl_Position = vec4(p * 2.0 - 1.0, 0.0, 1.0);
        })";
    static const char* kFragment = R"(#version 450 core
        layout(location = 0) out vec4 o_color;
        void main() { o_color = vec4(gl_FragCoord.xy * 1e-3, 0.0, 1.0); })";
    auto stage = [](GLenum type, const char* source) {
        gl::ShaderHandle shader(glCreateShader(type));
        glShaderSource(shader.id(), 1, &source, nullptr);
        glCompileShader(shader.id());
        return shader;
    };
    const gl::ShaderHandle vs = stage(GL_VERTEX_SHADER, kVertex), fs = stage(GL_FRAGMENT_SHADER, kFragment);
    const gl::ProgramHandle program(glCreateProgram());
    glAttachShader(program.id(), vs.id());
    glAttachShader(program.id(), fs.id());
    glLinkProgram(program.id());
    GLint linked = 0;
    glGetProgramiv(program.id(), GL_LINK_STATUS, &linked);
    if (!linked) return 0.0;
    const gl::Texture target = gl::Texture::create(GL_TEXTURE_2D, GL_RGBA16F, width, height, 1, 1, "bench.floor");
    const gl::FramebufferHandle framebuffer = gl::createFramebuffer();
    glNamedFramebufferTexture(framebuffer.id(), GL_COLOR_ATTACHMENT0, target.id(), 0);
    const gl::VertexArrayHandle vao = gl::createVertexArray();
    glBindFramebuffer(GL_FRAMEBUFFER, framebuffer.id());
    glViewport(0, 0, width, height);
    glDisable(GL_DEPTH_TEST);
    glUseProgram(program.id());
    glBindVertexArray(vao.id());
    // Wall time around each draw, with a glFinish on both sides: timestamp queries
    // around this one draw (flushed or not) read 0.05 ms on llvmpipe, a fraction of
    // it; a pass's queries bracket its framebuffer's whole scene.
    std::vector<double> ms;
    for (int i = 0; i < draws + 3; ++i) {
        glFinish();
        const auto t0 = std::chrono::steady_clock::now();
        glDrawArrays(GL_TRIANGLES, 0, 3);
        glFinish();
        const auto t1 = std::chrono::steady_clock::now();
        if (i >= 3) ms.push_back(std::chrono::duration<double, std::milli>(t1 - t0).count());
    }
    glBindVertexArray(0);
    glUseProgram(0);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    return ms.empty() ? 0.0 : median(ms);
}

// One round of `config`: a fresh app, --settle seconds simulated, 3 warm-up frames,
// then `frames` timed ones.
bool measureRound(const Args& args, const Config& config, const std::string& text, Measured& m, std::string& error) {
    app::Options o;
    app::applyDefaults(o);
    o.headless = true;
    o.width = args.width;
    o.height = args.height;
    o.pipeline = config.pipeline;
    if (!config.scene.empty()) o.scene = config.scene;
    app::App app;
    if (!app.init(o, error) || !app.runtime().loadPipelineText(text, config.pipeline, error)) return false;
    app.runtime().alwaysRun = true;
    while (app.scene().time() + 1e-9 < args.settle) app.scene().step();
    auto frame = [&] { frameMoving(app, args.stepsPerFrame); };
    for (int f = 0; f < 3; ++f) frame();
    glFinish();
    app.runtime().resetTimings();  // only the frames after warm-up count
    std::vector<double> walls;
    for (int f = 0; f < args.frames; ++f) {
        auto t0 = std::chrono::steady_clock::now();
        frame();
        glFinish();
        walls.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
    }
    // A pass that failed (a shader that does not compile, a module's ctx.fail) did not
    // do its work: its configuration has no honest time.
    if (auto errors = app.runtime().activeErrors(); !errors.empty()) {
        error = config.label + ": " + errors.front();
        return false;
    }
    app.runtime().collectGpuTimes();
    m.frameMs.push_back(median(walls));
    m.particles.push_back(double(app.scene().sim().particles().size()));
    const bool first = m.order.empty();
    for (auto& row : app.runtime().stats()) {
        if (first) m.order.push_back(row.id);
        if (row.ranFrames == 0) continue;
        m.gpu[row.id].push_back(row.gpuMedianMs);
        m.cpu[row.id].push_back(row.cpuMedianMs);
    }
    return true;
}

// floorMs: the empty pass's (emptyPassMs); 0 leaves the multiples out.
void report(const Config& config, Measured& m, double floorMs, std::ofstream& csv) {
    std::printf("%s\n  %-14s %10s %10s %9s\n", config.label.c_str(), "pass", "gpu ms", "cpu ms", "x floor");
    double total = 0;
    auto multiple = [&](double ms) { return floorMs > 0.0 ? ms / floorMs : 0.0; };
    for (auto& id : m.order) {
        if (!m.gpu.count(id)) continue;
        double g = median(m.gpu[id]), c = median(m.cpu[id]);
        total += g;
        std::printf("  %-14s %10.2f %10.2f %9.1f\n", id.c_str(), g, c, multiple(g));
        csv << '"' << config.label << "\"," << id << ",," << g << "," << c << "," << median(m.frameMs) << ","
            << multiple(g) << "\n";
    }
    std::printf("  %-14s %10.2f %10s %9.1f   frame (wall, glFinish) %.2f ms\n\n", "sum", total, "", multiple(total),
                median(m.frameMs));
}

}  // namespace

// growth.csv and growth.png: frame cost against the grown body count, per pipeline.
// `ratio` divides the medians over rounds; `paired` is the median over rounds of each
// round's ratio to the first count measured in the same round, with its lowest and
// highest: the machine's speed drifts between rounds by more than the two frames
// differ within one (on the 2-core machine, ±10 % from minute to minute).
void reportGrowth(const Args& args, const std::string& device, const std::vector<Config>& configs,
                  std::vector<Measured>& measured) {
    const std::string csvPath = (fs::path(args.outDir) / "growth.csv").string();
    std::ofstream csv(csvPath);
    csv << "pipeline," << args.growKind
        << ",particles,frame_ms,ratio,voxelize_ms,gbuffer_ms,shadow_ms,paired_ratio,paired_min,paired_max\n";
    std::printf("growth: frame cost against %s (ratio to the first count of the same pipeline; paired: the median, "
                "lowest and highest of each round's ratio)\n", args.growKind.c_str());
    std::printf("  %-10s %9s %10s %9s %7s %11s %10s %9s  %s\n", "pipeline", args.growKind.c_str(), "particles",
                "frame ms", "ratio", "voxelize ms", "gbuffer ms", "shadow ms", "paired (min-max)");
    std::map<std::string, size_t> base;  // the pipeline's first count's index
    for (size_t i = 0; i < configs.size(); ++i) {
        const std::string pipeline = fs::path(configs[i].pipeline).stem().string();
        Measured& m = measured[i];
        if (!base.count(pipeline)) base[pipeline] = i;
        const Measured& b = measured[base[pipeline]];
        const double frame = median(m.frameMs), ratio = frame / median(b.frameMs);
        std::vector<double> rounds;  // frameMs holds one median a round, in the rounds' order
        for (size_t r = 0; r < m.frameMs.size() && r < b.frameMs.size(); ++r)
            rounds.push_back(m.frameMs[r] / b.frameMs[r]);
        if (rounds.empty()) rounds.push_back(ratio);
        const double paired = median(rounds);
        const auto [low, high] = std::minmax_element(rounds.begin(), rounds.end());
        auto gpu = [&](const char* id) { return m.gpu.count(id) ? median(m.gpu[id]) : 0.0; };
        std::printf("  %-10s %9d %10.0f %9.2f %7.2f %11.2f %10.2f %9.2f  %.2f (%.2f-%.2f)\n", pipeline.c_str(),
                    configs[i].grown, median(m.particles), frame, ratio, gpu("voxelize"), gpu("gbuffer"), gpu("shadow"),
                    paired, *low, *high);
        csv << pipeline << "," << configs[i].grown << "," << median(m.particles) << "," << frame << "," << ratio << ","
            << gpu("voxelize") << "," << gpu("gbuffer") << "," << gpu("shadow") << "," << paired << "," << *low << ","
            << *high << "\n";
    }
    csv.close();  // complete on disk before the plot script reads it
    std::string error;
    const std::string png = (fs::path(args.outDir) / "growth.png").string();
    const std::string about = kiln::plotAbout(args.width, args.height, device);
    if (kiln::drawPlot({"growth", csvPath, png, "--about", about}, error)) std::printf("wrote %s and %s\n", csvPath.c_str(), png.c_str());
    else std::fprintf(stderr, "kiln-bench-render: %s: %s\n", png.c_str(), error.c_str());
}

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
    std::printf("device: %s\nsize %dx%d, %d frames x %d rounds (medians), every pass every frame, the scene moving\n\n",
                context->description().c_str(), args.width, args.height, args.frames, args.repeats);

    fs::create_directories(args.outDir);
    const std::string csvPath = (fs::path(args.outDir) / "render.csv").string();
    std::ofstream csv(csvPath);
    csv << "config,pass,module,gpu_ms,cpu_ms,frame_ms,x_floor\n";
    std::vector<std::string> texts(configs.size());
    for (size_t i = 0; i < configs.size(); ++i)
        if (!applyOverrides(slurp(configs[i].pipeline), configs[i].overrides, texts[i], error)) {
            std::fprintf(stderr, "kiln-bench-render: error: %s: %s\n", configs[i].pipeline.c_str(), error.c_str());
            return 1;
        }
    std::vector<Measured> measured(configs.size());
    std::vector<double> floors;  // per round, measured beside the configurations
    cli::Progress progress("pipelines timed", args.repeats * int(configs.size()));
    for (int round = 0; round < args.repeats; ++round) {
        floors.push_back(emptyPassMs(args.width, args.height, std::max(args.frames, 20)));
        for (size_t i = 0; i < configs.size(); ++i) {
            if (!measureRound(args, configs[i], texts[i], measured[i], error)) {
                std::fprintf(stderr, "kiln-bench-render: error: %s: %s\n", configs[i].pipeline.c_str(), error.c_str());
                return 1;
            }
            progress.advance(round * int(configs.size()) + int(i) + 1);
        }
    }
    const double floorMs = median(floors);
    std::printf("floor: an empty full-screen pass at %dx%d (its coordinates written to RGBA16F) takes %.3f ms (wall, glFinish)\n\n",
                args.width, args.height, floorMs);
    for (size_t i = 0; i < configs.size(); ++i) report(configs[i], measured[i], floorMs, csv);
    if (!args.growKind.empty()) reportGrowth(args, context->description(), configs, measured);
    std::printf("wrote %s\n", csvPath.c_str());
    return 0;
}
