// kiln-soak — a long headless run of the default scene (its fireballs included) at a
// small size, with a burst of live edits in the middle (a shader edit, a pipeline
// parameter edit and a scene reload, each applied and reverted through the real file
// watcher on temporary copies of the files), watching for leaks and bad values:
//   RSS (every 10 frames; growth before the edit burst, across it and after it, each
//   the difference of the means of two neighbouring stretches), bytes of the textures the host owns, open file
//   descriptors and threads at the end of warm-up (10 %, ≥ 100 frames) and at the end; GL errors (the debug callback's count); NaN/Inf in a
//   read-back of every texture every --scan-every frames.
// Prints a table, writes JSON (--out DIR, soak.json) and exits 1 if anything grew beyond
// its tolerance after warm-up (RSS: --rss-tolerance-mb, default 16; textures, fds,
// threads: none), any GL error was counted, or any texture held a NaN/Inf.
//   kiln-soak [--frames N=10000] [--size WxH=64x64] [--scan-every N=500] [--out DIR=bench-out]
//             [--edit-rounds N=3] [--rss-tolerance-mb MB=16] [--trace (RSS at every scan)]
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>
#include <string>
#include <vector>

#include "app/app.hpp"
#include "app/context.hpp"
#include "kiln/gl.hpp"
#include "kiln/image_io.hpp"
#include "kiln/log.hpp"

namespace fs = std::filesystem;
using namespace kiln;
using Clock = std::chrono::steady_clock;

namespace {

std::string slurp(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

// An editor's save: a temporary file renamed over the original.
void save(const fs::path& p, const std::string& text) {
    const fs::path tmp = p.parent_path() / ("." + p.filename().string() + ".new");
    std::ofstream(tmp, std::ios::trunc | std::ios::binary) << text;
    fs::rename(tmp, p);
}

size_t countEntries(const char* dir) {
    std::error_code ec;
    size_t n = 0;
    for (auto it = fs::directory_iterator(dir, ec); !ec && it != fs::directory_iterator(); it.increment(ec)) ++n;
    return n;
}

uint64_t rssBytes() {
    std::ifstream in("/proc/self/statm");
    uint64_t size = 0, resident = 0;
    in >> size >> resident;
    return resident * uint64_t(sysconf(_SC_PAGESIZE));
}

size_t texelBytes(GLenum f) {
    switch (f) {
        case GL_R8: return 1;
        case GL_R16F: case GL_RG8: return 2;
        case GL_RGBA8: case GL_SRGB8_ALPHA8: case GL_R32F: case GL_RG16F: case GL_R11F_G11F_B10F:
        case GL_DEPTH_COMPONENT32F: case GL_DEPTH_COMPONENT24: case GL_DEPTH24_STENCIL8: case GL_R32UI: return 4;
        case GL_RGBA16F: case GL_RG32F: return 8;
        case GL_RGBA32F: return 16;
        default: return 16;  // unknown: counted generously
    }
}

// Bytes of every texture the runtime owns (all mip levels).
uint64_t textureBytes(const run::Runtime& rt, size_t& count) {
    uint64_t bytes = 0;
    count = 0;
    for (const run::NamedTexture& t : rt.textures()) {
        const TextureRef& r = t.ref;
        if (!r.id) continue;
        ++count;
        const bool is3D = r.target == GL_TEXTURE_3D;
        for (int l = 0; l < std::max(1, r.levels); ++l) {
            const uint64_t w = std::max(1, r.width >> l), h = std::max(1, r.height >> l),
                           d = is3D ? std::max(1, r.depth >> l) : 1;
            bytes += w * h * d * texelBytes(r.format);
        }
    }
    return bytes;
}

// Non-finite values in a read-back of every texture (3D: every slice of level 0).
size_t nonFinite(const run::Runtime& rt, std::string& where) {
    size_t bad = 0;
    for (const run::NamedTexture& t : rt.textures()) {
        const TextureRef& r = t.ref;
        if (!r.id) continue;
        const int layers = r.target == GL_TEXTURE_3D ? r.depth : 1;
        for (int layer = 0; layer < layers; ++layer) {
            FloatImage img = readTexture(r.id, r.target, r.format, r.width, r.height, 0, r.target == GL_TEXTURE_3D ? layer : -1);
            for (float v : img.pixels)
                if (!std::isfinite(v)) {
                    if (!bad) where = t.pass + "." + t.name;
                    ++bad;
                }
        }
    }
    return bad;
}

struct Sample {
    uint64_t frame = 0, rss = 0, glBytes = 0, glErrors = 0;
    size_t textures = 0, fds = 0, threads = 0;
};

}  // namespace

int main(int argc, char** argv) {
    int frames = 10000, width = 64, height = 64, scanEvery = 500, rounds = 3;
    bool trace = false;
    double rssToleranceMb = 16.0;
    std::string outDir = "bench-out";
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        const bool hasValue = i + 1 < argc;
        if (a == "--frames" && hasValue) frames = std::atoi(argv[++i]);
        else if (a == "--size" && hasValue && std::sscanf(argv[++i], "%dx%d", &width, &height) == 2) {}
        else if (a == "--scan-every" && hasValue) scanEvery = std::atoi(argv[++i]);
        else if (a == "--rss-tolerance-mb" && hasValue) rssToleranceMb = std::atof(argv[++i]);
        else if (a == "--out" && hasValue) outDir = argv[++i];
        else if (a == "--edit-rounds" && hasValue) rounds = std::atoi(argv[++i]);
        else if (a == "--trace") trace = true;
        else {
            std::fprintf(stderr, "kiln-soak: error: unknown or incomplete option \"%s\"\n", a.c_str());
            return 2;
        }
    }
    if (frames < 100 || width < 8 || height < 8 || width > 4096 || height > 4096 || scanEvery < 1) {
        std::fprintf(stderr, "kiln-soak: error: --frames ≥ 100, --size from 8x8 to 4096x4096, --scan-every ≥ 1\n");
        return 2;
    }
    std::string error;
    auto context = app::HeadlessContext::create(/*debug=*/true, error);
    if (!context) {
        std::fprintf(stderr, "kiln-soak: error: %s\n", error.c_str());
        return 1;
    }
    log::setMinLevel(log::Level::Error);

    // Temporary copies the edits go to (the real watcher watches them).
    const fs::path root = fs::temp_directory_path() / ("kiln-soak-" + std::to_string(getpid()));
    fs::remove_all(root);
    fs::create_directories(root / "scenes");
    fs::copy(fs::path(KILN_SOURCE_DIR) / "shaders", root / "shaders", fs::copy_options::recursive);
    fs::copy(fs::path(KILN_SOURCE_DIR) / "pipelines", root / "pipelines", fs::copy_options::recursive);
    fs::copy_file(fs::path(KILN_SOURCE_DIR) / "scenes/cornell.json", root / "scenes/cornell.json");
    const fs::path frag = root / "shaders/composite/composite.frag", pipeline = root / "pipelines/default.json",
                   scene = root / "scenes/cornell.json";
    const std::string fragText = slurp(frag), pipelineText = slurp(pipeline), sceneText = slurp(scene);

    app::Options o;
    app::applyDefaults(o);
    o.headless = true;
    o.width = width, o.height = height;
    o.shaderRoot = (root / "shaders").string();
    o.pipeline = pipeline.string();
    o.scene = scene.string();
    int status = 0;
    {
        app::App app;
        if (!app.init(o, error)) {
            std::fprintf(stderr, "kiln-soak: error: %s\n", error.c_str());
            fs::remove_all(root);
            return 1;
        }
        run::Runtime& rt = app.runtime();
        auto sample = [&](uint64_t frame) {
            Sample s;
            s.frame = frame;
            s.rss = rssBytes();
            s.glBytes = textureBytes(rt, s.textures);
            s.glErrors = gl::debugErrorCount();
            s.fds = countEntries("/proc/self/fd");
            s.threads = countEntries("/proc/self/task");
            return s;
        };
        // Frames until `done` (or 10 s): a live edit is applied by the watcher after its
        // debounce, so this waits in real time.
        auto until = [&](int& frame, const std::function<bool()>& done) {
            const auto t0 = Clock::now();
            while (!done() && Clock::now() - t0 < std::chrono::seconds(10)) {
                app.frame();
                ++frame;
            }
            return done();
        };
        const uint64_t errorsAtStart = gl::debugErrorCount();
        const int warmup = std::max(100, frames / 10), burstAt = frames / 2;
        size_t nanCount = 0, scans = 0;
        std::string nanWhere;
        int editsApplied = 0, editsMissed = 0;
        Sample atWarmup, atEnd;
        const auto t0 = Clock::now();
        int frame = 0;
        bool burstDone = false;
        int burstEnd = frames;
        // RSS every 10 frames: it moves by ±10 MiB from frame to frame (the driver's
        // allocations), so growth compares the mean of the first quarter after warm-up
        // with the mean of the last quarter, not two single readings.
        std::vector<std::pair<int, uint64_t>> rssTrace;
        while (frame < frames) {
            app.frame();
            ++frame;
            if (frame == warmup) atWarmup = sample(frame);
            if (frame >= warmup && frame % 10 == 0) rssTrace.push_back({frame, rssBytes()});
            if (frame % scanEvery == 0) {
                ++scans;
                nanCount += nonFinite(rt, nanWhere);
                if (trace) std::printf("  frame %6d  RSS %7.1f MiB\n", frame, rssBytes() / 1048576.0);
            }
            if (frame >= burstAt && !burstDone) {
                burstDone = true;
                // The burst: three rounds of shader, pipeline and scene edits, each
                // applied and then reverted, waiting for the watcher each time.
                auto& live = app.live();
                for (int round = 0; round < rounds; ++round) {
                    const int s0 = live.shaderReloads, p0 = live.pipelineReloads, c0 = live.sceneReloads;
                    save(frag, fragText.substr(0, fragText.rfind('}')) + "    o_color.rgb *= 0.5;\n}\n");
                    std::string edited = pipelineText;
                    const size_t at = edited.find("\"exposure\"");
                    if (at != std::string::npos) {
                        const size_t colon = edited.find(':', at), end = edited.find_first_of(",}\n", colon);
                        edited.replace(colon + 1, end - colon - 1, " 0.5");
                    }
                    save(pipeline, edited);
                    save(scene, sceneText + "\n");  // same scene, new bytes: a reload (world reset)
                    const bool applied = until(frame, [&] {
                        return live.shaderReloads > s0 && live.pipelineReloads > p0 && live.sceneReloads > c0;
                    });
                    save(frag, fragText);
                    save(pipeline, pipelineText);
                    save(scene, sceneText);
                    const bool reverted = until(frame, [&] {
                        return live.shaderReloads > s0 + 1 && live.pipelineReloads > p0 + 1 && live.sceneReloads > c0 + 1;
                    });
                    (applied && reverted ? editsApplied : editsMissed) += 6;
                }
                burstEnd = frame;
            }
        }
        const double seconds = std::chrono::duration<double>(Clock::now() - t0).count();
        ++scans;
        nanCount += nonFinite(rt, nanWhere);
        atEnd = sample(frame);
        const uint64_t glErrors = gl::debugErrorCount() - errorsAtStart;
        // A leak grows with frames: before the burst and after it, the second half of the
        // stretch against its first half. What the edits cost once (new programs, the
        // driver's caches for them) is the step across the burst.
        auto meanMib = [&](int from, int to) {
            double sum = 0;
            int n = 0;
            for (auto& [f, rss] : rssTrace)
                if (f >= from && f < to) sum += double(rss), ++n;
            return n ? sum / n / (1 << 20) : 0.0;
        };
        const int preMid = (warmup + burstAt) / 2, postMid = (burstEnd + frame) / 2;
        const double early = meanMib(warmup, preMid) * (1 << 20), late = meanMib(postMid, frame + 1) * (1 << 20);
        const double growthBefore = meanMib(preMid, burstAt) - meanMib(warmup, preMid);
        const double stepAcross = meanMib(burstEnd, postMid) - meanMib(preMid, burstAt);
        const double growthAfter = meanMib(postMid, frame + 1) - meanMib(burstEnd, postMid);
        const double rssGrowthMb = std::max({growthBefore, stepAcross, growthAfter});

        std::vector<std::string> problems;
        if (growthBefore > rssToleranceMb) problems.push_back("RSS grew " + std::to_string(growthBefore) + " MiB before the edits");
        if (stepAcross > rssToleranceMb) problems.push_back("RSS rose " + std::to_string(stepAcross) + " MiB across the edits");
        if (growthAfter > rssToleranceMb) problems.push_back("RSS grew " + std::to_string(growthAfter) + " MiB after the edits");
        if (atEnd.glBytes != atWarmup.glBytes) problems.push_back("texture bytes changed after warm-up");
        if (atEnd.textures != atWarmup.textures) problems.push_back("texture count changed after warm-up");
        if (atEnd.fds > atWarmup.fds) problems.push_back("open file descriptors grew");
        if (atEnd.threads > atWarmup.threads) problems.push_back("threads grew");
        if (glErrors) problems.push_back(std::to_string(glErrors) + " GL errors");
        if (nanCount) problems.push_back(std::to_string(nanCount) + " NaN/Inf values (first in " + nanWhere + ")");
        if (editsMissed) problems.push_back(std::to_string(editsMissed) + " live edits not applied within 10 s");
        status = problems.empty() ? 0 : 1;

        std::printf("kiln-soak: %d frames at %dx%d in %.1f s (%.0f frames/s), live edits applied %d, missed %d\n", frame,
                    width, height, seconds, frame / seconds, editsApplied, editsMissed);
        std::printf("  %-22s %14s %14s %12s\n", "", "warm-up", "end", "tolerance");
        std::printf("  %-22s %14llu %14llu %12s\n", "frame", (unsigned long long)atWarmup.frame, (unsigned long long)atEnd.frame, "");
        std::printf("  %-22s %14.1f %14.1f %12s\n", "RSS (MiB)", atWarmup.rss / 1048576.0, atEnd.rss / 1048576.0, "");
        std::printf("  %-22s %14.1f %14.1f %12s\n", "RSS mean, first/last", early / 1048576.0, late / 1048576.0, "");
        const std::string tol = "+" + std::to_string(int(rssToleranceMb));
        std::printf("  %-22s %14s %14.1f %12s\n", "RSS growth before edits", "", growthBefore, tol.c_str());
        std::printf("  %-22s %14s %14.1f %12s\n", "RSS step across edits", "", stepAcross, tol.c_str());
        std::printf("  %-22s %14s %14.1f %12s\n", "RSS growth after edits", "", growthAfter, tol.c_str());
        std::printf("  %-22s %14llu %14llu %12s\n", "texture bytes", (unsigned long long)atWarmup.glBytes,
                    (unsigned long long)atEnd.glBytes, "equal");
        std::printf("  %-22s %14zu %14zu %12s\n", "textures", atWarmup.textures, atEnd.textures, "equal");
        std::printf("  %-22s %14zu %14zu %12s\n", "open fds", atWarmup.fds, atEnd.fds, "no growth");
        std::printf("  %-22s %14zu %14zu %12s\n", "threads", atWarmup.threads, atEnd.threads, "no growth");
        std::printf("  %-22s %14s %14llu %12s\n", "GL errors", "", (unsigned long long)glErrors, "0");
        std::printf("  %-22s %14s %14zu %12s\n", ("NaN/Inf (" + std::to_string(scans) + " scans)").c_str(), "", nanCount, "0");
        for (auto& p : problems) std::printf("kiln-soak: FAIL: %s\n", p.c_str());
        if (problems.empty()) std::printf("kiln-soak: ok\n");

        std::error_code ec;
        fs::create_directories(outDir, ec);
        std::ofstream json(fs::path(outDir) / "soak.json");
        auto s = [](const Sample& x) {
            return "{\"frame\": " + std::to_string(x.frame) + ", \"rss_bytes\": " + std::to_string(x.rss) +
                   ", \"texture_bytes\": " + std::to_string(x.glBytes) + ", \"textures\": " + std::to_string(x.textures) +
                   ", \"fds\": " + std::to_string(x.fds) + ", \"threads\": " + std::to_string(x.threads) + "}";
        };
        json << "{\n  \"frames\": " << frame << ",\n  \"width\": " << width << ",\n  \"height\": " << height
             << ",\n  \"seconds\": " << seconds << ",\n  \"warmup\": " << s(atWarmup) << ",\n  \"end\": " << s(atEnd)
             << ",\n  \"rss_mean_first_bytes\": " << uint64_t(early)
             << ",\n  \"rss_mean_last_bytes\": " << uint64_t(late) << ",\n  \"rss_growth_before_edits_mib\": " << growthBefore
             << ",\n  \"rss_step_across_edits_mib\": " << stepAcross << ",\n  \"rss_growth_after_edits_mib\": " << growthAfter
             << ",\n  \"rss_growth_mib\": " << rssGrowthMb << ",\n  \"rss_tolerance_mib\": " << rssToleranceMb
             << ",\n  \"gl_errors\": " << glErrors << ",\n  \"nan_inf\": " << nanCount << ",\n  \"scans\": " << scans
             << ",\n  \"live_edits_applied\": " << editsApplied << ",\n  \"live_edits_missed\": " << editsMissed
             << ",\n  \"ok\": " << (status == 0 ? "true" : "false") << "\n}\n";
        std::printf("wrote %s/soak.json\n", outDir.c_str());
    }
    fs::remove_all(root);
    return status;
}
