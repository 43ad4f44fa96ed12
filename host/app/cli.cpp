#include "app/cli.hpp"

#include <charconv>
#include <cstring>
#include <filesystem>
#include <string_view>

namespace kiln::app {

const char* kUsage = R"(kiln — a render-pass framework with hot reload

usage: kiln [options]

  --pipeline FILE   pipeline graph (default pipelines/default.json)
  --scene FILE      scene description (default scenes/cornell.json)
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
  --seed N          simulation seed (same seed, same frames)
  --paused          do not advance the simulation
  --shaders DIR     shader root (default shaders/)
  --modules DIRS    pass module directories, ':'-separated (default: the build's modules/)
  --help            this text

Window keys and mouse:
  drag a tumbler below its centre   move it on the floor
  drag a tumbler above its centre   tilt it (it rolls the matching distance)
  drag empty space                  orbit the camera          wheel  zoom
  Space  pause/resume   .  single step   R  reset the scene
  M  spawn a marble     F  spawn a fireball
  F1  toggle the debug view              Esc  quit
)";

namespace {
bool parseInt(std::string_view s, long long& out) {
    auto r = std::from_chars(s.data(), s.data() + s.size(), out);
    return r.ec == std::errc() && r.ptr == s.data() + s.size();
}
}  // namespace

void applyDefaults(Options& o) {
    const std::filesystem::path source = KILN_SOURCE_DIR;
    if (o.pipeline.empty()) o.pipeline = (source / "pipelines/default.json").string();
    if (o.scene.empty()) o.scene = (source / "scenes/cornell.json").string();
    if (o.shaderRoot.empty()) o.shaderRoot = (source / "shaders").string();
    if (o.moduleDir.empty()) o.moduleDir = KILN_MODULE_DIR;
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
                   a == "--shaders" || a == "--modules" || a == "--view" || a == "--screenshot") {
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
        } else if (a == "--frames" || a == "--seed") {
            auto v = value(a);
            if (!v) return std::nullopt;
            long long n = 0;
            if (!parseInt(*v, n) || n < (a == "--frames" ? 1 : 0)) {
                error = std::string(a) + " " + *v + ": expected a " + (a == "--frames" ? "positive" : "non-negative") + " integer";
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
