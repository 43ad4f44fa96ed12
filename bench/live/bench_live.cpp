// kiln-bench-live — save-to-new-frame latency of live edits, headless at 720×720:
// a shader edit, a pipeline edit and a module swap, 20 each (median and max), from the
// moment the file is written to the first frame whose pixels show the change. A
// command, not a test: prints a table and writes bench-out/live.csv.
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <thread>

#include "app/app.hpp"
#include "app/context.hpp"
#include "app/editable_copy.hpp"
#include "command_line/command_line.hpp"
#include "kiln/log.hpp"

namespace fs = std::filesystem;
using namespace kiln;
using Clock = std::chrono::steady_clock;

namespace {

glm::vec3 centrePixel(app::App& app) {
    const TextureRef* t = app.displayedTexture();
    float px[4] = {};
    glGetTextureSubImage(t->id, 0, t->width / 2, t->height / 2, 0, 1, 1, 1, GL_RGBA, GL_FLOAT, sizeof px, px);
    return {px[0], px[1], px[2]};
}

// Frames until the centre pixel is `want` (or, with `away`, no longer is); the time
// from `t0` in ms, or −1 after 5 s.
double until(app::App& app, glm::vec3 want, Clock::time_point t0, bool away = false) {
    while (Clock::now() - t0 < std::chrono::seconds(5)) {
        app.frame();
        if ((glm::length(centrePixel(app) - want) < 0.02f) != away)
            return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
    }
    return -1.0;
}

struct Stats { double median, max; };
Stats stats(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return {v[v.size() / 2], v.back()};
}

}  // namespace

int main(int argc, char** argv) {
    int trials = 20;
    std::string outDir = "bench-out";
    CLI::App app{"kiln-bench-live — save to new pixels, headless at 720x720: a shader edit, a pipeline edit and a\n"
                 "module swap, each timed from the file's write to the first frame that shows it (median and\n"
                 "max), a few seconds with 20 trials. Writes OUT/live.csv.",
                 "kiln-bench-live"};
    cli::configure(app);
    app.add_option("--trials", trials, "edits of each kind (default 20)")->type_name("N")->check(CLI::Range(2, 10000));
    app.add_option("--out", outDir, "where the CSV goes (default bench-out)")->type_name("DIR");
    if (const std::optional<int> exitNow = cli::parse(app, argc, argv)) return *exitNow;
    std::string error;
    auto context = app::HeadlessContext::create(false, error);
    if (!context) {
        std::fprintf(stderr, "kiln-bench-live: error: %s\n", error.c_str());
        return 1;
    }
    log::setMinLevel(log::Level::Error);
    const app::EditableCopy copy(fs::temp_directory_path() / ("kiln-bench-live-" + std::to_string(getpid())),
                                 app::defaultDataRoot());
    const fs::path& root = copy.root();
    const fs::path v1 = fs::path(LIVE_MODULE_BUILDS) / "tint_v1.so", v2 = fs::path(LIVE_MODULE_BUILDS) / "tint_v2.so";
    const bool haveModules = fs::exists(v1) && fs::exists(v2);
    if (haveModules) fs::copy_file(v1, root / "modules/libpass_live_tint.so");

    auto makeApp = [&](const std::string& pipeline, app::App& a) {
        app::Options o;
        app::applyDefaults(o);
        o.headless = true;
        o.paused = true;
        copy.pointAt(o, pipeline);
        return a.init(o, error);
    };
    std::vector<std::pair<std::string, std::vector<double>>> results;

    {  // Shader edit: composite.frag's final colour alternates.
        app::App a;
        if (!makeApp("default.json", a)) return std::fprintf(stderr, "kiln-bench-live: error: %s\n", error.c_str()), 1;
        a.frame();
        const fs::path frag = root / "shaders/composite/composite.frag";
        const std::string original = app::readWholeFile(frag);
        const std::string body = original.substr(0, original.rfind('}'));
        std::vector<double> ms;
        for (int i = 0; i < trials; ++i) {
            const bool odd = i % 2;
            app::saveByRename(frag, body + (odd ? "    o_color = vec4(1.0, 0.0, 1.0, 1.0);\n}\n" : "    o_color = vec4(0.0, 1.0, 0.0, 1.0);\n}\n"));
            ms.push_back(until(a, odd ? glm::vec3(1, 0, 1) : glm::vec3(0, 1, 0), Clock::now()));
        }
        app::saveByRename(frag, original);
        results.push_back({"shader edit", ms});
    }
    {  // Pipeline edit: composite's exposure alternates between 0.3 and 1.
        const fs::path file = root / "pipelines/default.json";
        std::string text = app::readWholeFile(file);
        app::App a;
        if (!makeApp("default.json", a)) return 1;
        a.frame();
        std::vector<double> ms;
        for (int i = 0; i < trials; ++i) {
            const glm::vec3 before = centrePixel(a);
            std::string edited = text;
            const std::string from = "\"exposure\": 1.0";
            edited.replace(edited.find(from), from.size(), i % 2 == 0 ? "\"exposure\": 0.3" : "\"exposure\": 1.0");
            app::saveByRename(file, edited);
            ms.push_back(until(a, before, Clock::now(), /*away=*/true));
        }
        results.push_back({"pipeline edit", ms});
    }
    if (haveModules) {  // Module swap: a rebuilt library replaces the running one.
        std::ofstream(root / "pipelines/tint.json")
            << R"({"output": "tint.color", "passes": [{"id": "tint", "module": "live_tint", "params": {"level": 0.25}}]})";
        app::App a;
        if (!makeApp("tint.json", a)) return std::fprintf(stderr, "kiln-bench-live: error: %s\n", error.c_str()), 1;
        a.frame();
        const std::string bytes[2] = {app::readWholeFile(v1), app::readWholeFile(v2)};
        std::vector<double> ms;
        for (int i = 0; i < trials; ++i) {
            const int next = (i + 1) % 2;  // starts on v1: first swap installs v2
            app::saveByRename(root / "modules/libpass_live_tint.so", bytes[next]);
            ms.push_back(until(a, next == 0 ? glm::vec3(1, 0.25f, 0) : glm::vec3(0, 0.25f, 1), Clock::now()));
        }
        results.push_back({"module swap", ms});
    }

    fs::create_directories(outDir);
    std::ofstream csv(fs::path(outDir) / "live.csv");
    csv << "edit,trial,ms\n";
    std::printf("save-to-new-frame latency, 720x720 headless, %d trials (a save is read at the next frame)\n", trials);
    std::printf("  %-15s %10s %10s\n", "edit", "median ms", "max ms");
    for (auto& [name, ms] : results) {
        for (size_t i = 0; i < ms.size(); ++i) csv << name << "," << i << "," << ms[i] << "\n";
        Stats s = stats(ms);
        std::printf("  %-15s %10.1f %10.1f\n", name.c_str(), s.median, s.max);
    }
    std::printf("wrote %s/live.csv\n", outDir.c_str());
    return 0;
}
