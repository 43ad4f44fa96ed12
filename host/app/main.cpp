// kiln — the host program: reads a pipeline graph, loads its pass modules, and runs
// it in a window (GLFW + Dear ImGui) or headless (EGL) into PNG files.
#include <GLFW/glfw3.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include "app/app.hpp"
#include "app/cli.hpp"
#include "app/context.hpp"
#include "kiln/guard.hpp"
#include "kiln/image_io.hpp"
#include "kiln/log.hpp"

namespace fs = std::filesystem;
using namespace kiln;
using namespace kiln::app;

namespace {

int fail(const std::string& message) {
    log::error(message);  // every line prefixed
    return 1;
}

int runHeadless(const Options& o) {
    std::string error;
    auto context = HeadlessContext::create(/*debug=*/true, error);
    if (!context) return fail(error);
    log::info("headless: ", context->description());
    App app;
    if (!app.init(o, error)) return fail(error);

    app.runtime().alwaysRun = o.noSkip;
    for (int f = 0; f < o.frames; ++f) app.frame();
    glFinish();
    app.runtime().collectGpuTimes();

    if (!o.out.empty()) {
        const TextureRef* out = app.displayedTexture();
        if (!out) return fail("the pipeline produced no output texture");
        FloatImage img = readTexture(out->id, out->target, out->format, out->width, out->height);
        if (!writePng(o.out, img, 3, error)) return fail(error);
        log::info("wrote ", o.out, " (", img.width, "x", img.height, ")");
    }
    if (!o.dump.empty()) {
        if (!app.runtime().dump(o.dump, error)) return fail(error);
        log::info("dumped ", app.runtime().textures().size(), " textures to ", o.dump);
    }
    if (o.stats) std::printf("%s", app.runtime().statsTable().c_str());
    // Each error was printed when it arose; this line only says why the exit status is 1.
    if (const size_t standing = app.runtime().activeErrors().size())
        return fail(str(standing, standing == 1 ? " error" : " errors", " still standing after the last frame (above)"));
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    std::string error;
    auto parsed = parseOptions(argc, argv, error);
    if (!parsed) return fail(error);
    Options o = *parsed;
    if (o.help) {
        std::printf("%s", usage().c_str());
        return 0;
    }
    applyDefaults(o);
    guard::setWatchdogLimit(std::chrono::seconds(o.watchdogSeconds));
    if (o.headless) return runHeadless(o);
    return runWindow(o);
}
