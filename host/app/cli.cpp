#include "app/cli.hpp"

#include <algorithm>
#include <charconv>
#include <cstring>
#include <filesystem>
#include <string_view>

#include "kiln/data_root.hpp"

namespace kiln::app {

const char* kUsage = R"(kiln — a render-pass framework with hot reload

usage: kiln [options]

  --pipeline FILE   pipeline graph (default pipelines/default.json, see below)
  --scene FILE      scene description (default scenes/cornell.json, see below)
  --headless        render with EGL, no window
  --size WxH        output size (default 720x720)
  --frames N        frames to render in headless mode (default 1)
  --out FILE.png    write the final image (headless)
  --watch           headless: keep running after --frames frames, rewrite --out
                    (and --dump) after every frame in which a live edit landed,
                    until interrupted (SIGINT/SIGTERM); a preview for an image viewer
  --dump DIR        headless: write every texture of the last frame (PNG, and OpenEXR for
                    float/depth); window: where the texture window's "save" writes
                    (default ./kiln-saves)
  --stats           print the per-pass time table (GPU timer queries + CPU clock)
  --no-live         do not watch files for live reloading
  --no-skip         run every pass every frame, even when nothing it reads changed
  --full-redraw     redraw the whole picture when only bodies moved (not their footprints)
  --plan            print the compiled plan (order, culled passes and why)
  --dot FILE        write the plan as graphviz dot
  --view PASS.OUT   show this texture instead of the graph output (un-culls its producer)
  --screenshot F    window mode: save the window (debug view included) after
                    --frames frames, then quit
  --budget MS       window: lower the render resolution while frames take
                    longer than MS (default 100; 0 keeps full resolution)
  --ui-probe FILE   window mode: keep FILE (JSON) up to date with where each
                    debug-view widget is on screen and what the texture readout
                    says, so scripts (xdotool) can drive the window
  --watchdog S      a pass's execute() (or a module's load) running longer than
                    S seconds is interrupted and named (default 10; 0: never)
  --seed N          simulation seed (same seed, same frames)
  --paused          do not advance the simulation
  --shaders DIRS    shader roots, ':'-separated, the first that has a file wins,
                    all watched; an empty entry is the shipped shaders/ (see
                    below): "--shaders mine:" searches mine/, then them
  --modules DIRS    pass module directories, the same way ("--modules mine:")
  --help            this text

Window keys and mouse:
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

namespace {
bool parseInt(std::string_view s, long long& out) {
    auto r = std::from_chars(s.data(), s.data() + s.size(), out);
    return r.ec == std::errc() && r.ptr == s.data() + s.size();
}
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

void applyDefaults(Options& o) {
    const std::filesystem::path root = defaultDataRoot();
    if (o.pipeline.empty()) o.pipeline = (root / "pipelines/default.json").string();
    if (o.scene.empty()) o.scene = (root / "scenes/cornell.json").string();
    o.shaderRoot = withShipped(o.shaderRoot, (root / "shaders").string());
    o.moduleDir = withShipped(o.moduleDir, shippedFiles().modules.string());
}

std::string usage() {
    return std::string(kUsage) + "\nDefault pipeline, scene and shaders come from " + defaultDataRoot().string() +
           "\n  (the working directory when it has pipelines/default.json and shaders/, else " +
           shippedFiles().describe() + ")\n";
}

namespace {

// Switches: each sets one field.
struct Switch {
    std::string_view name;
    bool Options::*field;
    bool value;
};
constexpr Switch kSwitches[] = {{"--help", &Options::help, true},        {"-h", &Options::help, true},
                                {"--headless", &Options::headless, true}, {"--stats", &Options::stats, true},
                                {"--no-live", &Options::live, false},     {"--no-skip", &Options::noSkip, true},
                                {"--plan", &Options::printPlan, true},    {"--paused", &Options::paused, true},
                                {"--watch", &Options::watch, true},       {"--full-redraw", &Options::fullRedraw, true}};

// Options whose value is kept as text (paths, a texture name).
struct TextOption {
    std::string_view name;
    std::string Options::*field;
};
constexpr TextOption kTextOptions[] = {
    {"--pipeline", &Options::pipeline}, {"--scene", &Options::scene},     {"--out", &Options::out},
    {"--dump", &Options::dump},         {"--dot", &Options::dot},         {"--shaders", &Options::shaderRoot},
    {"--modules", &Options::moduleDir}, {"--view", &Options::view},       {"--screenshot", &Options::screenshot},
    {"--ui-probe", &Options::uiProbe}};

bool parseSize(const std::string& v, Options& o, std::string& error) {
    const auto x = v.find('x');
    long long w = 0, h = 0;
    if (x == std::string::npos || !parseInt(std::string_view(v).substr(0, x), w) ||
        !parseInt(std::string_view(v).substr(x + 1), h) || w < 1 || h < 1 || w > 16384 || h > 16384) {
        error = "--size " + v + ": expected WxH with 1 <= W, H <= 16384 (e.g. 720x720)";
        return false;
    }
    o.width = static_cast<int>(w);
    o.height = static_cast<int>(h);
    return true;
}

// --budget, --watchdog, --frames, --seed: whole numbers, bounded where the value lands
// (frames in an int, the seed in 63 bits: parseInt's range), so nothing wraps.
bool parseNumber(std::string_view a, const std::string& v, Options& o, std::string& error) {
    constexpr long long kMaxFrames = 1'000'000'000;
    long long n = 0;
    const bool parsed = parseInt(v, n);
    if (a == "--budget" || a == "--watchdog") {
        const bool budget = a == "--budget";
        const long long most = budget ? 100000 : 86400;
        if (!parsed || n < 0 || n > most) {
            error = std::string(a) + " " + v + ": expected " + (budget ? "milliseconds" : "whole seconds") + ", 0 to " +
                    std::to_string(most) + (budget ? " (0: off)" : " (0: never)");
            return false;
        }
        (budget ? o.budgetMs : o.watchdogSeconds) = static_cast<int>(n);
    } else if (a == "--frames") {
        if (!parsed || n < 1 || n > kMaxFrames) {
            error = std::string(a) + " " + v + ": expected a whole number of frames from 1 to " + std::to_string(kMaxFrames);
            return false;
        }
        o.frames = static_cast<int>(n);
    } else {
        if (!parsed || n < 0) {
            error = std::string(a) + " " + v + ": expected a non-negative integer";
            return false;
        }
        o.seed = static_cast<uint64_t>(n);
    }
    return true;
}

}  // namespace

std::optional<Options> parseOptions(int argc, char** argv, std::string& error) {
    Options o;
    for (int i = 1; i < argc; ++i) {
        const std::string_view a = argv[i];
        const Switch* flag = std::find_if(std::begin(kSwitches), std::end(kSwitches), [&](auto& f) { return f.name == a; });
        if (flag != std::end(kSwitches)) {
            o.*(flag->field) = flag->value;
            continue;
        }
        const TextOption* text =
            std::find_if(std::begin(kTextOptions), std::end(kTextOptions), [&](auto& t) { return t.name == a; });
        const bool number = a == "--budget" || a == "--watchdog" || a == "--frames" || a == "--seed";
        if (text == std::end(kTextOptions) && !number && a != "--size") {
            error = "unknown argument \"" + std::string(a) + "\" (see kiln --help)";
            return std::nullopt;
        }
        if (i + 1 >= argc) {
            error = std::string(a) + " needs a value";
            return std::nullopt;
        }
        const std::string v = argv[++i];
        if (text != std::end(kTextOptions)) o.*(text->field) = v;
        else if (a == "--size" ? !parseSize(v, o, error) : !parseNumber(a, v, o, error)) return std::nullopt;
    }
    if (o.watch && (!o.headless || !o.live || (o.out.empty() && o.dump.empty()))) {
        error = "--watch keeps a headless run going and rewrites its files after each live edit: it needs --headless "
                "and --out or --dump, and not --no-live";
        return std::nullopt;
    }
    return o;
}

}  // namespace kiln::app
