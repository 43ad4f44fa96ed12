// kiln-bench-scene — what a glTF file costs before and after its first frame, headless:
// the load (parse, check, flatten: model::loadGltf), the upload and first frame of the
// default pipeline at --size, and save → new pixels with the file placed in a scene and
// watched (a material's base colour rewritten in place of the file, by rename, until
// the centre pixel changes). Medians and maxima over --trials. A command, not a test:
// prints a table and writes bench-out/scene.csv.
//   kiln-bench-scene [--size WxH] [--trials N] [--out DIR] FILE.gltf|FILE.glb...
//   kiln-bench-scene [--size WxH] --grow triangles=N1,N2,...|lights=N1,N2,...
// --grow: a generated model (an 8 × 8 grid of spheres on the box's floor, N triangles in
// all; or 100 000 of them under N point lights, which cast no shadows) in the box, and the
// default pipeline's frame, every pass every frame, the median of --trials frames after
// three, against the first N's.
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>

#include "app/app.hpp"
#include "app/context.hpp"
#include "app/editable_copy.hpp"
#include "command_line/command_line.hpp"
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

// A .glb of an 8 × 8 grid of UV spheres on the floor, about `triangles` in all, and
// `lights` point lights in a ring above them.
std::string gridGlb(uint64_t triangles, int lights) {
    const int seg = std::max(3, int(std::lround(std::sqrt(double(triangles) / 64.0 / 4.0))));  // 4·seg² a sphere
    std::vector<float> pos, nrm;
    std::vector<uint32_t> idx;
    for (int gz = 0; gz < 8; ++gz)
        for (int gx = 0; gx < 8; ++gx) {
            const glm::vec3 c(-0.7f + 0.2f * float(gx), -0.92f, -0.7f + 0.2f * float(gz));
            const uint32_t base = uint32_t(pos.size() / 3);
            for (int i = 0; i <= seg; ++i)
                for (int j = 0; j <= 2 * seg; ++j) {
                    const float th = 3.14159265f * float(i) / float(seg), ph = 3.14159265f * float(j) / float(seg);
                    const glm::vec3 n(std::sin(th) * std::cos(ph), std::cos(th), std::sin(th) * std::sin(ph));
                    const glm::vec3 p = c + 0.08f * n;
                    pos.insert(pos.end(), {p.x, p.y, p.z});
                    nrm.insert(nrm.end(), {n.x, n.y, n.z});
                }
            for (int i = 0; i < seg; ++i)
                for (int j = 0; j < 2 * seg; ++j) {
                    const uint32_t a = base + uint32_t(i * (2 * seg + 1) + j), b = a + uint32_t(2 * seg + 1);
                    idx.insert(idx.end(), {a, a + 1, b, a + 1, b + 1, b});
                }
        }
    std::string bin;
    auto append = [&](const void* p, size_t n) { bin.append(static_cast<const char*>(p), n); };
    append(pos.data(), pos.size() * 4);
    append(nrm.data(), nrm.size() * 4);
    append(idx.data(), idx.size() * 4);
    const size_t vcount = pos.size() / 3;
    nlohmann::json j = {
        {"asset", {{"version", "2.0"}}}, {"scene", 0}, {"scenes", {{{"nodes", {0}}}}}, {"nodes", {{{"mesh", 0}}}},
        {"meshes", {{{"primitives", {{{"attributes", {{"POSITION", 0}, {"NORMAL", 1}}}, {"indices", 2}}}}}}},
        {"accessors", {{{"bufferView", 0}, {"componentType", 5126}, {"count", vcount}, {"type", "VEC3"}},
                       {{"bufferView", 1}, {"componentType", 5126}, {"count", vcount}, {"type", "VEC3"}},
                       {{"bufferView", 2}, {"componentType", 5125}, {"count", idx.size()}, {"type", "SCALAR"}}}},
        {"bufferViews", {{{"buffer", 0}, {"byteOffset", 0}, {"byteLength", vcount * 12}},
                         {{"buffer", 0}, {"byteOffset", vcount * 12}, {"byteLength", vcount * 12}},
                         {{"buffer", 0}, {"byteOffset", vcount * 24}, {"byteLength", idx.size() * 4}}}},
        {"buffers", {{{"byteLength", bin.size()}}}}};
    if (lights > 0) {
        j["extensionsUsed"] = {"KHR_lights_punctual"};
        nlohmann::json list = nlohmann::json::array();
        for (int l = 0; l < lights; ++l) {
            list.push_back({{"type", "point"}, {"intensity", 1.0 / lights}});
            const float a = 6.2831853f * float(l) / float(lights);
            j["nodes"].push_back({{"translation", {0.5 * std::cos(a), 0.2, 0.5 * std::sin(a)}},
                                  {"extensions", {{"KHR_lights_punctual", {{"light", l}}}}}});
            j["scenes"][0]["nodes"].push_back(l + 1);
        }
        j["extensions"] = {{"KHR_lights_punctual", {{"lights", list}}}};
    }
    std::string text = j.dump();
    while (text.size() % 4) text += ' ';
    std::string out(20, '\0');
    const uint32_t version = 2, total = uint32_t(20 + text.size() + 8 + bin.size()), length = uint32_t(text.size()),
                   jsonType = 0x4E4F534Au, binLength = uint32_t(bin.size()), binType = 0x004E4942u;
    std::memcpy(out.data(), "glTF", 4);
    std::memcpy(out.data() + 4, &version, 4);
    std::memcpy(out.data() + 8, &total, 4);
    std::memcpy(out.data() + 12, &length, 4);
    std::memcpy(out.data() + 16, &jsonType, 4);
    std::string chunk(8, '\0');
    std::memcpy(chunk.data(), &binLength, 4);
    std::memcpy(chunk.data() + 4, &binType, 4);
    return out + text + chunk + bin;
}

// The default pipeline's frame with the scene file `scene`, every pass every frame: the
// median of `frames` after three.
double frameMs(const std::string& scene, int width, int height, int frames, std::string& error) {
    app::App a;
    app::Options o;
    app::applyDefaults(o);
    o.headless = true, o.paused = true, o.live = false, o.width = width, o.height = height;
    o.scene = scene;
    if (!a.init(o, error)) return -1.0;
    a.runtime().alwaysRun = true;
    std::vector<double> ms;
    for (int f = 0; f < frames + 3; ++f) {
        const auto t0 = Clock::now();
        a.frame();
        glFinish();
        if (f >= 3) ms.push_back(msSince(t0));
    }
    return medianMax(ms).first;
}

int grow(const std::string& spec, int width, int height, int frames, const std::string& outDir) {
    const size_t eq = spec.find('=');
    const std::string kind = spec.substr(0, eq);
    if (eq == std::string::npos || (kind != "triangles" && kind != "lights")) {
        std::fprintf(stderr, "kiln-bench-scene: --grow %s: expected triangles=N1,N2,... or lights=N1,N2,...\n", spec.c_str());
        return 2;
    }
    std::vector<uint64_t> counts;
    for (size_t at = eq + 1; at < spec.size();) {
        size_t end = spec.find(',', at);
        if (end == std::string::npos) end = spec.size();
        char* stop = nullptr;
        const std::string v = spec.substr(at, end - at);
        const unsigned long long n = std::strtoull(v.c_str(), &stop, 10);
        if (v.empty() || *stop || (kind == "lights" && n > uint64_t(kMaxPunctualLights)) || (kind == "triangles" && (n < 100 || n > 4'000'000))) {
            std::fprintf(stderr, "kiln-bench-scene: --grow %s: %s is no count (triangles 100..4000000, lights 0..%d)\n",
                         spec.c_str(), v.c_str(), kMaxPunctualLights);
            return 2;
        }
        counts.push_back(n);
        at = end + 1;
    }
    std::string error;
    const fs::path dir = fs::temp_directory_path() / ("kiln-bench-scene-grow-" + std::to_string(getpid()));
    fs::create_directories(dir);
    fs::create_directories(outDir);
    std::ofstream csv(fs::path(outDir) / ("grow_" + kind + ".csv"));
    csv << kind << ",triangles,frame_ms,ratio\n";
    std::printf("the default pipeline's frame, %dx%d, every pass every frame, median of %d frames\n", width, height, frames);
    std::printf("  %10s %10s %10s %8s\n", kind.c_str(), "triangles", "frame ms", "ratio");
    double first = 0.0;
    for (uint64_t n : counts) {
        const uint64_t triangles = kind == "triangles" ? n : 100'000;
        const int lights = kind == "lights" ? int(n) : 0;
        std::ofstream(dir / "grid.glb", std::ios::binary) << gridGlb(triangles, lights);
        model::Model m;
        if (!model::loadGltf((dir / "grid.glb").string(), m, error)) return std::fprintf(stderr, "kiln-bench-scene: error: %s\n", error.c_str()), 1;
        std::ofstream(dir / "scene.json") << R"({"tumblers": [], "models": [{"file": "grid.glb"}]})";
        const double ms = frameMs((dir / "scene.json").string(), width, height, frames, error);
        if (ms < 0.0) return std::fprintf(stderr, "kiln-bench-scene: error: %s\n", error.c_str()), 1;
        if (first == 0.0) first = ms;
        std::printf("  %10llu %10llu %10.1f %8.2f\n", (unsigned long long)n, (unsigned long long)m.triangles(), ms, ms / first);
        csv << n << "," << m.triangles() << "," << ms << "," << ms / first << "\n";
    }
    fs::remove_all(dir);
    std::printf("wrote %s\n", (fs::path(outDir) / ("grow_" + kind + ".csv")).string().c_str());
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    int width = 256, height = 256, trials = 10;
    std::string outDir = "bench-out";
    std::vector<std::string> files;
    std::string growSpec;
    CLI::App app{"kiln-bench-scene — for each glTF file: load (parse, check, flatten), first frame (scene load,\n"
                 "upload and the default pipeline's first frame) and save->pixels (a material's colour saved until\n"
                 "the centre pixel changes); --grow: the frame with a generated model of more and more triangles\n"
                 "or lights. A few seconds a file at 256x256 with 10 trials. Writes OUT/scene.csv or OUT/grow_*.csv.",
                 "kiln-bench-scene"};
    cli::configure(app);
    cli::addSize(app, "--size", width, height, 16, 16384, "the picture's size (default 256x256)");
    app.add_option("--trials", trials, "trials per file, the median kept (default 10)")->type_name("N")->check(CLI::Range(2, 1 << 20));
    app.add_option("--out", outDir, "where the CSV goes (default bench-out)")->type_name("DIR");
    app.add_option("--grow", growSpec, "a generated model instead of files")->type_name("triangles|lights=N1,N2");
    app.add_option("files", files, "glTF files (.gltf, .glb)")->type_name("FILE");
    if (const std::optional<int> exitNow = cli::parse(app, argc, argv)) return *exitNow;
    if (files.empty() == growSpec.empty()) return cli::usageError(app, "give glTF files or --grow, not both and not neither");
    std::string error;
    auto context = app::HeadlessContext::create(false, error);
    if (!context) {
        std::fprintf(stderr, "kiln-bench-scene: error: %s\n", error.c_str());
        return 1;
    }
    log::setMinLevel(log::Level::Error);
    if (!growSpec.empty()) return grow(growSpec, width, height, trials, outDir);
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
