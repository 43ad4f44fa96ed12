// kiln-bench-scene — what a glTF file costs before and after its first frame, headless:
// the load (parse, check, flatten: model::loadGltf), the upload and first frame of the
// default pipeline at --size, and save → new pixels with the file placed in a scene and
// watched (a material's base colour rewritten in place of the file, by rename, until
// the centre pixel changes). Medians and maxima over --trials. A command, not a test:
// prints a table and writes bench-out/scene.csv.
//   kiln-bench-scene [--size WxH] [--trials N] [--out DIR] FILE.gltf|FILE.glb...
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>

#include "app/app.hpp"
#include "app/context.hpp"
#include "app/editable_copy.hpp"
#include "kiln/log.hpp"
#include "model/model.hpp"

namespace fs = std::filesystem;
using namespace kiln;
using Clock = std::chrono::steady_clock;

namespace {

double msSince(Clock::time_point t0) { return std::chrono::duration<double, std::milli>(Clock::now() - t0).count(); }

std::pair<double, double> medianMax(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return {v[v.size() / 2], v.back()};
}

glm::vec3 centrePixel(app::App& app) {
    const TextureRef* t = app.displayedTexture();
    float px[4] = {};
    glGetTextureSubImage(t->id, 0, t->width / 2, t->height / 2, 0, 1, 1, 1, GL_RGBA, GL_FLOAT, sizeof px, px);
    return {px[0], px[1], px[2]};
}

// The file's bytes with every material's base colour factor set to `rgb` (a .glb's JSON
// chunk rewritten and padded, its binary chunk kept). Empty when it has no material.
std::string recoloured(const std::string& bytes, float rgb) {
    const bool glb = bytes.size() >= 20 && std::memcmp(bytes.data(), "glTF", 4) == 0;
    uint32_t jsonLength = 0;
    if (glb) std::memcpy(&jsonLength, bytes.data() + 12, 4);
    nlohmann::json j = nlohmann::json::parse(glb ? bytes.substr(20, jsonLength) : bytes, nullptr, false);
    if (j.is_discarded() || !j.contains("materials")) return {};
    for (auto& m : j["materials"]) m["pbrMetallicRoughness"]["baseColorFactor"] = {rgb, rgb, rgb, 1.0};
    std::string text = j.dump();
    if (!glb) return text;
    while (text.size() % 4) text += ' ';
    const std::string rest = bytes.substr(20 + jsonLength);
    std::string out(20, '\0');
    const uint32_t version = 2, total = uint32_t(20 + text.size() + rest.size()), length = uint32_t(text.size()),
                   type = 0x4E4F534Au;
    std::memcpy(out.data(), "glTF", 4);
    std::memcpy(out.data() + 4, &version, 4);
    std::memcpy(out.data() + 8, &total, 4);
    std::memcpy(out.data() + 12, &length, 4);
    std::memcpy(out.data() + 16, &type, 4);
    return out + text + rest;
}

[[noreturn]] void usage(int code) {
    std::fprintf(code ? stderr : stdout,
                 "usage: kiln-bench-scene [--size WxH] [--trials N] [--out DIR] FILE.gltf|FILE.glb...\n"
                 "  load: parse, check and flatten the file; first frame: scene load, upload and the\n"
                 "  default pipeline's first frame; save->pixels: a material's colour saved until the\n"
                 "  centre pixel changes. A few seconds a file at 256x256 with 10 trials.\n");
    std::exit(code);
}

}  // namespace

int main(int argc, char** argv) {
    int width = 256, height = 256, trials = 10;
    std::string outDir = "bench-out";
    std::vector<std::string> files;
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        auto next = [&]() -> std::string {
            if (i + 1 >= argc) usage(2);
            return argv[++i];
        };
        if (a == "--help" || a == "-h") usage(0);
        else if (a == "--size") {
            if (std::sscanf(next().c_str(), "%dx%d", &width, &height) != 2 || width < 16 || height < 16) usage(2);
        } else if (a == "--trials") trials = std::max(2, std::atoi(next().c_str()));
        else if (a == "--out") outDir = next();
        else if (a.rfind("--", 0) == 0) usage(2);
        else files.push_back(a);
    }
    if (files.empty()) usage(2);
    std::string error;
    auto context = app::HeadlessContext::create(false, error);
    if (!context) {
        std::fprintf(stderr, "kiln-bench-scene: error: %s\n", error.c_str());
        return 1;
    }
    log::setMinLevel(log::Level::Error);
    fs::create_directories(outDir);
    std::ofstream csv(fs::path(outDir) / "scene.csv");
    csv << "file,measure,trial,ms\n";
    std::printf("glTF files, %dx%d headless, %d trials (median / max ms)\n", width, height, trials);
    std::printf("  %-28s %10s %9s %16s %16s %18s\n", "file", "triangles", "MiB", "load", "first frame", "save->pixels");
    for (const std::string& file : files) {
        const std::string name = fs::path(file).filename().string();
        std::vector<double> load, first, save;
        model::Model m;
        for (int t = 0; t < trials; ++t) {
            const auto t0 = Clock::now();
            if (!model::loadGltf(file, m, error)) {
                std::fprintf(stderr, "kiln-bench-scene: error: %s\n", error.c_str());
                return 1;
            }
            load.push_back(msSince(t0));
        }
        // A copy of the file in a scene of its own, watched.
        const fs::path dir = fs::temp_directory_path() / ("kiln-bench-scene-" + std::to_string(getpid()));
        fs::create_directories(dir);
        const fs::path model = dir / fs::path(file).filename();
        fs::copy_file(file, model, fs::copy_options::overwrite_existing);
        for (const std::string& f : m.files)
            if (f != file) fs::copy_file(f, dir / fs::path(f).filename(), fs::copy_options::overwrite_existing);
        const fs::path sceneFile = dir / "scene.json";
        std::ofstream(sceneFile) << R"({"tumblers": [], "models": [{"file": ")" << model.filename().string()
                                 << R"(", "fit": true}]})";
        const std::string original = app::readWholeFile(model);
        for (int t = 0; t < std::max(1, trials / 3); ++t) {
            app::App a;
            app::Options o;
            app::applyDefaults(o);
            o.headless = true, o.paused = true, o.live = false, o.width = width, o.height = height;
            o.scene = sceneFile.string();
            const auto t0 = Clock::now();
            if (!a.init(o, error)) {
                std::fprintf(stderr, "kiln-bench-scene: error: %s\n", error.c_str());
                return 1;
            }
            a.frame();
            glFinish();
            first.push_back(msSince(t0));
        }
        {
            app::App a;
            app::Options o;
            app::applyDefaults(o);
            o.headless = true, o.paused = true, o.live = true, o.width = width, o.height = height;
            o.scene = sceneFile.string();
            if (!a.init(o, error)) return std::fprintf(stderr, "kiln-bench-scene: error: %s\n", error.c_str()), 1;
            a.frame();
            a.settle();
            for (int t = 0; t < trials; ++t) {
                const std::string bytes = recoloured(original, t % 2 ? 0.9f : 0.1f);
                if (bytes.empty()) break;
                const glm::vec3 before = centrePixel(a);
                const auto t0 = Clock::now();
                app::saveByRename(model, bytes);
                double ms = -1.0;
                while (Clock::now() - t0 < std::chrono::seconds(10)) {
                    a.frame();
                    if (glm::length(centrePixel(a) - before) > 0.01f) {
                        ms = msSince(t0);
                        break;
                    }
                }
                save.push_back(ms);
                a.settle();
            }
        }
        fs::remove_all(dir);
        auto cell = [](const std::vector<double>& v) {
            if (v.empty()) return std::string("-");
            const auto [med, max] = medianMax(v);
            char buf[64];
            std::snprintf(buf, sizeof buf, "%.1f / %.1f", med, max);
            return std::string(buf);
        };
        uint64_t bytes = 0;
        for (const std::string& f : m.files) bytes += fs::file_size(f);
        std::printf("  %-28s %10llu %9.1f %16s %16s %18s\n", name.c_str(), (unsigned long long)m.triangles(),
                    double(bytes) / double(1 << 20), cell(load).c_str(), cell(first).c_str(), cell(save).c_str());
        for (auto [measure, v] : {std::pair{"load", &load}, {"first_frame", &first}, {"save_to_pixels", &save}})
            for (size_t i = 0; i < v->size(); ++i) csv << name << "," << measure << "," << i << "," << (*v)[i] << "\n";
    }
    std::printf("wrote %s\n", (fs::path(outDir) / "scene.csv").string().c_str());
    return 0;
}
