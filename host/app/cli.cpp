#include "app/cli.hpp"

#include <algorithm>
#include <cctype>
#include <filesystem>

#include "command_line/command_line.hpp"
#include "graph/pipeline.hpp"
#include "kiln/data_root.hpp"

namespace kiln::app {

namespace {

constexpr const char* kWindowKeys = R"(Window keys and mouse:
  drag a tumbler below its centre   move it on the floor
  drag a tumbler above its centre   tilt it (it rolls the matching distance)
  drag empty space                  orbit the camera          wheel  zoom
  Space  pause/resume   .  single step   R  reset the scene
  M  spawn a marble     F  spawn a fireball
  F1  toggle the debug view              Esc (or Ctrl+C in the terminal)  quit
  right-click the image: trace that pixel through every pass's textures
  texture window: wheel zooms about the cursor, drag pans, hover reads the value
  compare view: drag the line across the image
)";

}  // namespace

std::filesystem::path defaultDataRoot() {
    namespace fs = std::filesystem;
    std::error_code ec;
    const fs::path cwd = fs::current_path(ec);
    // A copied tree edits and writes back its own files, not the ones it was built from.
    if (!ec && fs::is_regular_file(cwd / "pipelines/default.json", ec) && fs::is_regular_file(cwd / "shaders/common/frame.glsl", ec))
        return cwd;
    return shippedFiles().data;
}

namespace {

// An empty entry in a ':'-separated list stands for the shipped directory, as in MANPATH:
// "--shaders mine:" searches mine/, then the shipped shaders; "--shaders mine" only mine/
// (a file missing there is an error, never a silent fall-back to the shipped copy).
std::string withShipped(const std::string& list, const std::string& shipped) {
    if (list.empty()) return shipped;
    std::string out;
    for (size_t start = 0; start <= list.size();) {
        const size_t end = std::min(list.find(':', start), list.size());
        if (start > 0) out += ':';
        out += end > start ? list.substr(start, end - start) : shipped;
        start = end + 1;
    }
    return out;
}

}  // namespace

std::string imageFormatOf(const std::string& file) {
    std::string ext = std::filesystem::path(file).extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
    for (const char* known : {".png", ".exr", ".pfm"})
        if (ext == known) return ext.substr(1);
    return "";
}

std::vector<std::string> pathList(const std::string& list) {
    std::vector<std::string> out;
    for (size_t start = 0; start <= list.size();) {
        const size_t end = std::min(list.find(':', start), list.size());
        if (end > start) out.push_back(list.substr(start, end - start));
        start = end + 1;
    }
    return out;
}

void applyDefaults(Options& o) {
    const std::filesystem::path root = defaultDataRoot();
    if (o.pipeline.empty()) o.pipeline = (root / "pipelines/default.json").string();
    if (o.scene.empty()) o.scene = (root / "scenes/cornell.json").string();
    o.shaderRoot = withShipped(o.shaderRoot, (root / "shaders").string());
    o.moduleDir = withShipped(o.moduleDir, shippedFiles().modules.string());
}

namespace {


// The checks CLI11 cannot make: what a mode needs and which options it has no use for.
// Each returns "" or the one line that explains the refusal.
std::string checkCombination(const CLI::App& app, const Options& o) {
    auto given = [&](const char* name) { return app.count(name) > 0; };
    if (o.listModules || !o.describe.empty()) return "";
    for (const std::string& set : o.sets)
        if (!graph::parseParamOverride(set))
            return "--set " + set + ": expected PASS.PARAM=VALUE (e.g. --set shadow.size=1024)";
    if (!o.out.empty() && imageFormatOf(o.out).empty())
        return "--out " + o.out + ": the format follows the extension: .png (8 bits, display), .exr or .pfm (float)";
    if (o.watch && (!o.headless || !o.live || (o.out.empty() && o.dump.empty())))
        return "--watch keeps a headless run going and rewrites its files after each live edit: it needs --headless "
               "and --out or --dump, and not --no-live";
    if (o.headless) {
        for (const char* windowOnly : {"--window", "--screenshot", "--ui-probe", "--budget"})
            if (given(windowOnly))
                return std::string(windowOnly) + " is for the window; a headless run writes --out, --dump or --stats";
        if (o.out.empty() && o.dump.empty() && !o.stats && !o.printPlan && o.dot.empty())
            return "a headless run needs something to write: --out FILE, --dump DIR, --stats, --plan or --dot FILE";
    } else {
        for (const char* headlessOnly : {"--out", "--stats"})
            if (given(headlessOnly))
                return std::string(headlessOnly) + " is for --headless; the window saves with --screenshot FILE";
        if (!o.screenshot.empty() && imageFormatOf(o.screenshot) != "png")
            return "--screenshot " + o.screenshot + ": a screenshot is a .png";
    }
    return "";
}

}  // namespace

std::variant<Options, int> parseCommandLine(int argc, char** argv) {
    Options o;
    CLI::App app{"kiln — a render-pass framework with hot reload (OpenGL 4.5)", "kiln"};
    cli::configure(app);
    const char* input = "Input";
    app.add_option("--pipeline", o.pipeline, "the pipeline graph (default pipelines/default.json)")->type_name("FILE")->group(input);
    app.add_option("--scene", o.scene, "a scene JSON or a glTF 2.0 file (default scenes/cornell.json)")
        ->type_name("FILE")->group(input);
    app.add_option("--set", o.sets, "set a parameter over the file's value (repeatable; kept over reloads)")
        ->type_name("PASS.PARAM=VALUE")->allow_extra_args(false)->group(input);
    app.add_option("--shaders", o.shaderRoot, "shader roots, ':'-separated, first wins; an empty entry is the shipped ones")
        ->type_name("DIRS")->group(input);
    app.add_option("--modules", o.moduleDir, "pass module directories, the same way (\"--modules mine:\")")->type_name("DIRS")->group(input);
    long long seed = -1;
    app.add_option("--seed", seed, "simulation seed: the same seed, the same frames (default: the scene's)")
        ->type_name("N")->check(CLI::NonNegativeNumber.description(""))->group(input);

    const char* run = "Running";
    app.add_flag("--headless", o.headless, "render with EGL, no window")->group(run);
    cli::addSize(app, "--size", o.width, o.height, 1, 16384, "the picture's size (default 720x720)")->group(run);
    app.add_option("--frames", o.frames, "frames before the outputs (default 1); then up to 64 settling frames")
        ->type_name("N")->check(CLI::Range(1, 1'000'000'000))->group(run);
    app.add_flag("--paused", o.paused, "do not advance the simulation")->group(run);
    app.add_flag_callback("--no-live", [&o] { o.live = false; }, "do not watch files for live reloading")->group(run);
    app.add_flag("--no-skip", o.noSkip, "run every pass every frame, changed or not (timing)")->group(run);
    app.add_flag("--full-redraw", o.fullRedraw, "redraw all of the picture when only bodies moved")->group(run);
    app.add_option("--view", o.view, "show (and --out) this texture, not the graph's output")
        ->type_name("PASS.OUTPUT")->group(run);
    app.add_option("--watchdog", o.watchdogSeconds, "interrupt a pass's call after S seconds (default 10; 0: never)")
        ->type_name("S")->check(CLI::Range(0, 86400))->group(run);

    const char* headless = "Headless output";
    app.add_option("--out", o.out, "write the final image: .png, .exr or .pfm")->type_name("FILE")->group(headless);
    app.add_option("--dump", o.dump, "write every texture (PNG; EXR for float); window: where \"save\" writes")
        ->type_name("DIR")->group(headless);
    app.add_flag("--stats", o.stats, "print the time of each pass (GPU timer queries and CPU)")->group(headless);
    app.add_flag("--plan", o.printPlan, "print the compiled plan: order, culled passes and why")->group(headless);
    app.add_option("--dot", o.dot, "write the plan as graphviz dot")->type_name("FILE")->group(headless);
    app.add_flag("--watch", o.watch, "rewrite --out and --dump after each live edit, until Ctrl+C")->group(headless);

    const char* window = "Window";
    cli::addSize(app, "--window", o.windowWidth, o.windowHeight, 64, 16384,
                 "the window's size (default: --size plus the panels' column)")->group(window);
    app.add_option("--screenshot", o.screenshot, "save the window after --frames frames, then quit")
        ->type_name("FILE.png")->group(window);
    app.add_option("--budget", o.budgetMs, "lower the resolution while frames take > MS (default 100; 0: off)")
        ->type_name("MS")->check(CLI::Range(0, 100000))->group(window);
    app.add_option("--ui-probe", o.uiProbe, "keep FILE (JSON) saying where each widget is, for scripts")
        ->type_name("FILE")->group(window);

    const char* discover = "Discover (print and exit)";
    app.add_flag("--list-modules", o.listModules, "list the pass modules --modules finds")->group(discover);
    app.add_option("--describe", o.describe, "a module's inputs, outputs, parameters (Markdown; \"all\")")
        ->type_name("MODULE")->group(discover);

    app.footer(std::string(kWindowKeys) + "\nExit status: 0 done, 1 the run failed, 2 a usage error, 130 interrupted.\n" +
               "Default pipeline, scene and shaders come from " + defaultDataRoot().string() +
               "\n  (the working directory when it has pipelines/default.json and shaders/, else " +
               shippedFiles().describe() + ")\n");
    if (std::optional<int> exitNow = cli::parse(app, argc, argv)) return *exitNow;
    if (seed >= 0) o.seed = uint64_t(seed);
    if (const std::string wrong = checkCombination(app, o); !wrong.empty()) return cli::usageError(app, wrong);
    return o;
}

}  // namespace kiln::app
