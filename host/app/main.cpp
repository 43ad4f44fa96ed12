// kiln — the host program: reads a pipeline graph, loads its pass modules, and runs
// it in a window (GLFW + Dear ImGui) or headless (EGL) into PNG files.
#include <GLFW/glfw3.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <thread>

#include "app/app.hpp"
#include "app/cli.hpp"
#include "app/context.hpp"
#include "app/describe.hpp"
#include "app/stop_signal.hpp"
#include "command_line/command_line.hpp"
#include "kiln/guard.hpp"
#include "kiln/image_io.hpp"
#include "kiln/log.hpp"

namespace fs = std::filesystem;
using namespace kiln;
using namespace kiln::app;

namespace {

int fail(const std::string& message) {
    log::error(message);  // every line prefixed
    return cli::kExitFailure;
}

// The final image in the format its extension names (checked when parsing).
bool writeImage(const std::string& file, const FloatImage& img, std::string& error) {
    const std::string format = imageFormatOf(file);
    if (format == "exr") return writeExr(file, img, error);
    if (format == "pfm") return writePfm(file, img, error);
    return writePng(file, img, 3, error);
}

// Where the outputs go exists before anything renders: a run that cannot write its
// result fails in its first second, not after its last frame.
bool prepareOutputs(const Options& o, std::string& error) {
    auto ensureDirectory = [&](const fs::path& dir, const std::string& what) {
        if (dir.empty()) return true;
        std::error_code ec;
        fs::create_directories(dir, ec);
        if (fs::is_directory(dir)) return true;
        error = what + ": cannot create the directory " + dir.string() + (ec ? " (" + ec.message() + ")" : "");
        return false;
    };
    return ensureDirectory(fs::path(o.out).parent_path(), "--out " + o.out) &&
           ensureDirectory(fs::path(o.dot).parent_path(), "--dot " + o.dot) &&
           ensureDirectory(fs::path(o.screenshot).parent_path(), "--screenshot " + o.screenshot) &&
           ensureDirectory(o.dump.empty() || !o.headless ? fs::path() : fs::path(o.dump), "--dump " + o.dump);
}

// --out and --dump from the frame just rendered.
bool writeOutputs(App& app, const Options& o, std::string& error) {
    glFinish();
    if (!o.out.empty()) {
        const TextureRef* out = app.displayedTexture();
        if (!out) {
            error = "the pipeline produced no output texture";
            return false;
        }
        FloatImage img = readTexture(out->id, out->target, out->format, out->width, out->height);
        if (!writeImage(o.out, img, error)) return false;
        log::info("wrote ", o.out, " (", img.width, "x", img.height, ")");
    }
    if (!o.dump.empty()) {
        if (!app.runtime().dump(o.dump, error)) return false;
        log::info("dumped ", app.runtime().textures().size(), " textures to ", o.dump);
    }
    return true;
}

// --watch: frames go on (paced to ~60 a second, so an idle watch costs little) until
// SIGINT or SIGTERM; the outputs are rewritten after each frame in which an edit landed.
// A failed edit is reported by the live reloader and leaves the files as they were.
int watch(App& app, const Options& o) {
    catchStopSignals();
    log::info("watching for edits; the outputs are rewritten after each one (stop with Ctrl+C)");
    int applied = app.live().applied();
    while (!stopSignalled) {
        const auto next = std::chrono::steady_clock::now() + std::chrono::milliseconds(16);
        app.frame();
        if (app.live().applied() != applied) {
            applied = app.live().applied();
            app.settle();  // the edit's frame converged, as the first --out was
            std::string error;
            if (!writeOutputs(app, o, error)) log::error(error);
        }
        std::this_thread::sleep_until(next);
    }
    log::info("stopped watching");
    return exitStatusAfterStop();
}

int runHeadless(const Options& o) {
    std::string error;
    auto context = HeadlessContext::create(/*debug=*/true, error);
    if (!context) return fail(error);
    log::info("headless: ", context->description());
    App app;
    if (!app.init(o, error)) return fail(error);

    app.runtime().alwaysRun = o.noSkip;
    catchStopSignals();
    for (int f = 0; f < o.frames && !stopSignalled; ++f) app.frame();
    if (stopSignalled) return exitStatusAfterStop();
    // The outputs show the last frame's moment converged, not part way (voxel bounces
    // fed back gain one a frame).
    if (const int settled = app.settle()) log::info("settled in ", settled, settled == 1 ? " frame" : " frames");
    app.runtime().collectGpuTimes();
    if (!writeOutputs(app, o, error)) return fail(error);
    if (o.stats) std::printf("%s", app.runtime().statsTable().c_str());
    if (o.watch) return watch(app, o);
    // Each error was printed when it arose; this line only says why the exit status is 1.
    if (const size_t standing = app.runtime().activeErrors().size())
        return fail(str(standing, standing == 1 ? " error" : " errors", " still standing after the last frame (above)"));
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    auto parsed = parseCommandLine(argc, argv);
    if (const int* exitNow = std::get_if<int>(&parsed)) return *exitNow;
    Options o = std::get<Options>(parsed);
    applyDefaults(o);
    if (o.listModules) return listModules(o);
    if (!o.describe.empty()) return describeModules(o, o.describe);
    if (std::string error; !prepareOutputs(o, error)) return fail(error);
    guard::setWatchdogLimit(std::chrono::seconds(o.watchdogSeconds));
    if (o.headless) return runHeadless(o);
    return runWindow(o);
}
