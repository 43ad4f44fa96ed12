#include "app/cli.hpp"

#include <charconv>
#include <cstring>
#include <filesystem>
#include <string_view>

namespace kiln::app {

const char* kUsage = R"(kiln — a render-pass framework with hot reload

usage: kiln [options]

  --pipeline FILE   pipeline graph (default pipelines/default.json, see below)
  --scene FILE      scene description (default scenes/cornell.json, see below)
  --headless        render with EGL, no window
  --size WxH        output size (default 720x720)
  --frames N        frames to render in headless mode (default 1)
  --out FILE.png    write the final image (headless)
  --dump DIR        write every texture of the last frame (PNG, and OpenEXR for float/depth)
  --stats           print the per-pass time table (GPU timer queries + CPU clock)
  --no-live         do not watch files for live reloading
  --no-skip         run every pass every frame, even when nothing it reads changed
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
  --shaders DIR     shader root (default shaders/, see below)
  --modules DIRS    pass module directories, ':'-separated (default: the build's modules/)
  --help            this text

Window keys and mouse:
  drag a tumbler below its centre   move it on the floor
  drag a tumbler above its centre   tilt it (it rolls the matching distance)
  drag empty space                  orbit the camera          wheel  zoom
  Space  pause/resume   .  single step   R  reset the scene
  M  spawn a marble     F  spawn a fireball
  F1  toggle the debug view              Esc  quit
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
    return KILN_SOURCE_DIR;
}

void applyDefaults(Options& o) {
    const std::filesystem::path root = defaultDataRoot();
    if (o.pipeline.empty()) o.pipeline = (root / "pipelines/default.json").string();
    if (o.scene.empty()) o.scene = (root / "scenes/cornell.json").string();
    if (o.shaderRoot.empty()) o.shaderRoot = (root / "shaders").string();
    if (o.moduleDir.empty()) o.moduleDir = KILN_MODULE_DIR;
}

std::string usage() {
    return std::string(kUsage) + "\nDefault files come from " + defaultDataRoot().string() +
           "\n  (the working directory when it has pipelines/default.json and shaders/, else the source tree\n"
           "  Kiln was built from); modules from " + KILN_MODULE_DIR + "\n";
}

std::optional<Options> parseOptions(int argc, char** argv, std::string& error) {
    Options o;
    for (int i = 1; i < argc; ++i) {
        std::string_view a = argv[i];
        auto value = [&](std::string_view name) -> std::optional<std::string> {
            if (i + 1 >= argc) {
                error = std::string(name) + " needs a value";
                return std::nullopt;
            }
            return std::string(argv[++i]);
        };
        if (a == "--help" || a == "-h") {
            o.help = true;
        } else if (a == "--headless") {
            o.headless = true;
        } else if (a == "--stats") {
            o.stats = true;
        } else if (a == "--no-live") {
            o.live = false;
        } else if (a == "--no-skip") {
            o.noSkip = true;
        } else if (a == "--plan") {
            o.printPlan = true;
        } else if (a == "--paused") {
            o.paused = true;
        } else if (a == "--pipeline" || a == "--scene" || a == "--out" || a == "--dump" || a == "--dot" ||
                   a == "--shaders" || a == "--modules" || a == "--view" || a == "--screenshot" || a == "--ui-probe") {
            auto v = value(a);
            if (!v) return std::nullopt;
            std::string* dst = a == "--pipeline" ? &o.pipeline
                             : a == "--scene"    ? &o.scene
                             : a == "--out"      ? &o.out
                             : a == "--dump"     ? &o.dump
                             : a == "--dot"      ? &o.dot
                             : a == "--shaders"  ? &o.shaderRoot
                             : a == "--modules"  ? &o.moduleDir
                             : a == "--screenshot" ? &o.screenshot
                             : a == "--ui-probe" ? &o.uiProbe
                                                 : &o.view;
            *dst = *v;
        } else if (a == "--size") {
            auto v = value(a);
            if (!v) return std::nullopt;
            auto x = v->find('x');
            long long w = 0, h = 0;
            if (x == std::string::npos || !parseInt(std::string_view(*v).substr(0, x), w) ||
                !parseInt(std::string_view(*v).substr(x + 1), h) || w < 1 || h < 1 || w > 16384 || h > 16384) {
                error = "--size " + *v + ": expected WxH with 1 <= W, H <= 16384 (e.g. 720x720)";
                return std::nullopt;
            }
            o.width = static_cast<int>(w);
            o.height = static_cast<int>(h);
        } else if (a == "--budget" || a == "--watchdog") {
            auto v = value(a);
            if (!v) return std::nullopt;
            const bool budget = a == "--budget";
            const long long most = budget ? 100000 : 86400;
            long long n = 0;
            if (!parseInt(*v, n) || n < 0 || n > most) {
                error = std::string(a) + " " + *v + ": expected " + (budget ? "milliseconds" : "whole seconds") + ", 0 to " +
                        std::to_string(most) + (budget ? " (0: off)" : " (0: never)");
                return std::nullopt;
            }
            (budget ? o.budgetMs : o.watchdogSeconds) = static_cast<int>(n);
        } else if (a == "--frames" || a == "--seed") {
            auto v = value(a);
            if (!v) return std::nullopt;
            long long n = 0;
            // Bounded where the value lands: frames in an int, the seed in 63 bits (parseInt's
            // range), so nothing wraps into another number.
            constexpr long long kMaxFrames = 1'000'000'000;
            const bool frames = a == "--frames";
            if (!parseInt(*v, n) || n < (frames ? 1 : 0) || (frames && n > kMaxFrames)) {
                error = std::string(a) + " " + *v + ": expected " +
                        (frames ? "a whole number of frames from 1 to " + std::to_string(kMaxFrames) : std::string("a non-negative integer"));
                return std::nullopt;
            }
            if (a == "--frames") o.frames = static_cast<int>(n); else o.seed = static_cast<uint64_t>(n);
        } else {
            error = "unknown argument \"" + std::string(a) + "\" (see kiln --help)";
            return std::nullopt;
        }
    }
    return o;
}

}  // namespace kiln::app
