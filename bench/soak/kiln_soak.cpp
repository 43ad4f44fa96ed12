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
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "app/app.hpp"
#include "app/context.hpp"
#include "app/editable_copy.hpp"
#include "command_line/command_line.hpp"
#include "kiln/gl.hpp"
#include "kiln/image_io.hpp"
#include "kiln/log.hpp"

namespace fs = std::filesystem;
using namespace kiln;
using Clock = std::chrono::steady_clock;

namespace {

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

Sample sample(const run::Runtime& rt, uint64_t frame) {
    Sample s;
    s.frame = frame;
    s.rss = rssBytes();
    s.glBytes = textureBytes(rt, s.textures);
    s.glErrors = gl::debugErrorCount();
    s.fds = countEntries("/proc/self/fd");
    s.threads = countEntries("/proc/self/task");
    return s;
}

std::string toJson(const Sample& x) {
    return "{\"frame\": " + std::to_string(x.frame) + ", \"rss_bytes\": " + std::to_string(x.rss) +
           ", \"texture_bytes\": " + std::to_string(x.glBytes) + ", \"textures\": " + std::to_string(x.textures) +
           ", \"fds\": " + std::to_string(x.fds) + ", \"threads\": " + std::to_string(x.threads) + "}";
}

struct Options {
    int frames = 10000, width = 64, height = 64, scanEvery = 500, rounds = 3;
    bool trace = false;
    double rssToleranceMb = 16.0;
    std::string outDir = "bench-out";
};

std::optional<Options> parseOptions(int argc, char** argv, int& exitStatus) {
    Options o;
    CLI::App app{"kiln-soak — a long headless run of the default scene with a burst of live edits in the middle,\n"
                 "watching RSS, texture bytes, file descriptors, threads, GL errors and NaN/Inf in every texture;\n"
                 "exits 1 if anything grew or went bad. Writes OUT/soak.json.",
                 "kiln-soak"};
    cli::configure(app);
    app.add_option("--frames", o.frames, "frames in all, at least 300 (default 10000)")->type_name("N")->check(CLI::Range(300, 100'000'000));
    cli::addSize(app, "--size", o.width, o.height, 8, 4096, "the picture's size (default 64x64)");
    app.add_option("--scan-every", o.scanEvery, "frames between NaN/Inf scans of every texture (default 500)")
        ->type_name("N")->check(CLI::Range(1, 100'000'000));
    app.add_option("--rss-tolerance-mb", o.rssToleranceMb, "RSS growth allowed after warm-up (default 16)")->type_name("MB")->check(CLI::Range(0.0, 1e6));
    app.add_option("--edit-rounds", o.rounds, "rounds of the edit burst (default 3)")->type_name("N")->check(CLI::Range(0, 10000));
    app.add_flag("--trace", o.trace, "record RSS at every scan");
    app.add_option("--out", o.outDir, "where soak.json goes (default bench-out)")->type_name("DIR");
    if (const std::optional<int> exitNow = cli::parse(app, argc, argv)) {
        exitStatus = *exitNow;
        return std::nullopt;
    }
    return o;
}

// The three files the burst edits (in the editable copy), with their original text.
struct EditedFiles {
    fs::path frag, pipeline, scene;
    std::string fragText, pipelineText, sceneText;
    explicit EditedFiles(const fs::path& root)
        : frag(root / "shaders/composite/composite.frag"), pipeline(root / "pipelines/default.json"),
          scene(root / "scenes/cornell.json"), fragText(app::readWholeFile(frag)),
          pipelineText(app::readWholeFile(pipeline)), sceneText(app::readWholeFile(scene)) {}
};

// The run: frames, samples, the burst of edits in the middle; then what it found.
class Soak {
public:
    Soak(app::App& app, const Options& o, const EditedFiles& files) : app_(app), o_(o), files_(files) {}

    void run() {
        const uint64_t errorsAtStart = gl::debugErrorCount();
        const auto t0 = Clock::now();
        warmup_ = std::max(100, o_.frames / 10);
        burstAt_ = o_.frames / 2;
        burstEnd_ = o_.frames;
        bool burstDone = false;
        while (frame_ < o_.frames) {
            app_.frame();
            ++frame_;
            if (frame_ == warmup_) atWarmup_ = sample(app_.runtime(), frame_);
            if (frame_ >= warmup_ && frame_ % 10 == 0) rssTrace_.push_back({frame_, rssBytes()});
            if (frame_ % o_.scanEvery == 0) scan();
            if (frame_ >= burstAt_ && !burstDone) {
                burstDone = true;
                for (int round = 0; round < o_.rounds; ++round) (editRound() ? editsApplied_ : editsMissed_) += 6;
                burstEnd_ = frame_;
            }
        }
        seconds_ = std::chrono::duration<double>(Clock::now() - t0).count();
        scan();
        atEnd_ = sample(app_.runtime(), frame_);
        glErrors_ = gl::debugErrorCount() - errorsAtStart;
    }

    std::vector<std::string> problems() const {
        const double tolerance = o_.rssToleranceMb;
        std::vector<std::string> p;
        if (growthBefore() > tolerance) p.push_back("RSS grew " + std::to_string(growthBefore()) + " MiB before the edits");
        if (stepAcross() > tolerance) p.push_back("RSS rose " + std::to_string(stepAcross()) + " MiB across the edits");
        if (growthAfter() > tolerance) p.push_back("RSS grew " + std::to_string(growthAfter()) + " MiB after the edits");
        if (atEnd_.glBytes != atWarmup_.glBytes) p.push_back("texture bytes changed after warm-up");
        if (atEnd_.textures != atWarmup_.textures) p.push_back("texture count changed after warm-up");
        if (atEnd_.fds > atWarmup_.fds) p.push_back("open file descriptors grew");
        if (atEnd_.threads > atWarmup_.threads) p.push_back("threads grew");
        if (glErrors_) p.push_back(std::to_string(glErrors_) + " GL errors");
        if (nanCount_) p.push_back(std::to_string(nanCount_) + " NaN/Inf values (first in " + nanWhere_ + ")");
        if (editsMissed_)
            p.push_back(std::to_string(editsMissed_) + " live edits not applied within " +
                        std::to_string(kEditDeadline.count()) + " s");
        return p;
    }

    void printTable() const {
        std::printf("kiln-soak: %d frames at %dx%d in %.1f s (%.0f frames/s), live edits applied %d, missed %d\n", frame_,
                    o_.width, o_.height, seconds_, frame_ / seconds_, editsApplied_, editsMissed_);
        std::printf("  %-22s %14s %14s %12s\n", "", "warm-up", "end", "tolerance");
        std::printf("  %-22s %14llu %14llu %12s\n", "frame", (unsigned long long)atWarmup_.frame,
                    (unsigned long long)atEnd_.frame, "");
        std::printf("  %-22s %14.1f %14.1f %12s\n", "RSS (MiB)", atWarmup_.rss / 1048576.0, atEnd_.rss / 1048576.0, "");
        std::printf("  %-22s %14.1f %14.1f %12s\n", "RSS mean, first/last", meanMib(warmup_, preMid()),
                    meanMib(postMid(), frame_ + 1), "");
        const std::string tol = "+" + std::to_string(int(o_.rssToleranceMb));
        std::printf("  %-22s %14s %14.1f %12s\n", "RSS growth before edits", "", growthBefore(), tol.c_str());
        std::printf("  %-22s %14s %14.1f %12s\n", "RSS step across edits", "", stepAcross(), tol.c_str());
        std::printf("  %-22s %14s %14.1f %12s\n", "RSS growth after edits", "", growthAfter(), tol.c_str());
        std::printf("  %-22s %14llu %14llu %12s\n", "texture bytes", (unsigned long long)atWarmup_.glBytes,
                    (unsigned long long)atEnd_.glBytes, "equal");
        std::printf("  %-22s %14zu %14zu %12s\n", "textures", atWarmup_.textures, atEnd_.textures, "equal");
        std::printf("  %-22s %14zu %14zu %12s\n", "open fds", atWarmup_.fds, atEnd_.fds, "no growth");
        std::printf("  %-22s %14zu %14zu %12s\n", "threads", atWarmup_.threads, atEnd_.threads, "no growth");
        std::printf("  %-22s %14s %14llu %12s\n", "GL errors", "", (unsigned long long)glErrors_, "0");
        std::printf("  %-22s %14s %14zu %12s\n", ("NaN/Inf (" + std::to_string(scans_) + " scans)").c_str(), "",
                    nanCount_, "0");
    }

    void writeJson(const fs::path& file, bool ok) const {
        const double rssGrowthMb = std::max({growthBefore(), stepAcross(), growthAfter()});
        std::ofstream json(file);
        json << "{\n  \"frames\": " << frame_ << ",\n  \"width\": " << o_.width << ",\n  \"height\": " << o_.height
             << ",\n  \"seconds\": " << seconds_ << ",\n  \"warmup\": " << toJson(atWarmup_)
             << ",\n  \"end\": " << toJson(atEnd_)
             << ",\n  \"rss_mean_first_bytes\": " << uint64_t(meanMib(warmup_, preMid()) * (1 << 20))
             << ",\n  \"rss_mean_last_bytes\": " << uint64_t(meanMib(postMid(), frame_ + 1) * (1 << 20))
             << ",\n  \"rss_growth_before_edits_mib\": " << growthBefore()
             << ",\n  \"rss_step_across_edits_mib\": " << stepAcross()
             << ",\n  \"rss_growth_after_edits_mib\": " << growthAfter() << ",\n  \"rss_growth_mib\": " << rssGrowthMb
             << ",\n  \"rss_tolerance_mib\": " << o_.rssToleranceMb << ",\n  \"gl_errors\": " << glErrors_
             << ",\n  \"nan_inf\": " << nanCount_ << ",\n  \"scans\": " << scans_
             << ",\n  \"live_edits_applied\": " << editsApplied_ << ",\n  \"live_edits_missed\": " << editsMissed_
             << ",\n  \"ok\": " << (ok ? "true" : "false") << "\n}\n";
    }

private:
    // A live edit is applied by the watcher after its debounce, so the burst waits in
    // real time: generously, since a busy machine (a parallel ctest) slows every frame.
    static constexpr std::chrono::seconds kEditDeadline{60};

    void scan() {
        ++scans_;
        nanCount_ += nonFinite(app_.runtime(), nanWhere_);
        if (o_.trace) std::printf("  frame %6d  RSS %7.1f MiB\n", frame_, rssBytes() / 1048576.0);
    }

    // Frames until `done` (or the deadline).
    bool framesUntil(const std::function<bool()>& done) {
        const auto t0 = Clock::now();
        while (!done() && Clock::now() - t0 < kEditDeadline) {
            app_.frame();
            ++frame_;
        }
        return done();
    }

    // A shader, a pipeline parameter and a scene edit, applied, then reverted, waiting
    // for the watcher each time. True when all six reloads happened.
    bool editRound() {
        auto& live = app_.live();
        const int s0 = live.shaderReloads, p0 = live.pipelineReloads, c0 = live.sceneReloads;
        app::saveByRename(files_.frag, files_.fragText.substr(0, files_.fragText.rfind('}')) + "    o_color.rgb *= 0.5;\n}\n");
        std::string edited = files_.pipelineText;
        if (const size_t at = edited.find("\"exposure\""); at != std::string::npos) {
            const size_t colon = edited.find(':', at), end = edited.find_first_of(",}\n", colon);
            edited.replace(colon + 1, end - colon - 1, " 0.5");
        }
        app::saveByRename(files_.pipeline, edited);
        app::saveByRename(files_.scene, files_.sceneText + "\n");  // same scene, new bytes: a reload (world reset)
        const bool applied = framesUntil(
            [&] { return live.shaderReloads > s0 && live.pipelineReloads > p0 && live.sceneReloads > c0; });
        app::saveByRename(files_.frag, files_.fragText);
        app::saveByRename(files_.pipeline, files_.pipelineText);
        app::saveByRename(files_.scene, files_.sceneText);
        const bool reverted = framesUntil([&] {
            return live.shaderReloads > s0 + 1 && live.pipelineReloads > p0 + 1 && live.sceneReloads > c0 + 1;
        });
        return applied && reverted;
    }

    // RSS moves by ±10 MiB from frame to frame (the driver's allocations), so growth
    // compares the means of neighbouring stretches, not single readings. A leak grows
    // with frames: before the burst and after it, each stretch's second half against
    // its first; what the edits cost once (new programs, the driver's caches) is the
    // step across the burst.
    double meanMib(int from, int to) const {
        double sum = 0;
        int n = 0;
        for (auto& [f, rss] : rssTrace_)
            if (f >= from && f < to) sum += double(rss), ++n;
        return n ? sum / n / (1 << 20) : 0.0;
    }
    int preMid() const { return (warmup_ + burstAt_) / 2; }
    int postMid() const { return (burstEnd_ + frame_) / 2; }
    double growthBefore() const { return meanMib(preMid(), burstAt_) - meanMib(warmup_, preMid()); }
    double stepAcross() const { return meanMib(burstEnd_, postMid()) - meanMib(preMid(), burstAt_); }
    double growthAfter() const { return meanMib(postMid(), frame_ + 1) - meanMib(burstEnd_, postMid()); }

    app::App& app_;
    const Options& o_;
    const EditedFiles& files_;
    int frame_ = 0, warmup_ = 0, burstAt_ = 0, burstEnd_ = 0;
    int editsApplied_ = 0, editsMissed_ = 0;
    size_t nanCount_ = 0, scans_ = 0;
    std::string nanWhere_;
    Sample atWarmup_, atEnd_;
    uint64_t glErrors_ = 0;
    double seconds_ = 0;
    std::vector<std::pair<int, uint64_t>> rssTrace_;
};

}  // namespace

int main(int argc, char** argv) {
    int exitStatus = 0;
    const std::optional<Options> options = parseOptions(argc, argv, exitStatus);
    if (!options) return exitStatus;
    std::string error;
    auto context = app::HeadlessContext::create(/*debug=*/true, error);
    if (!context) {
        std::fprintf(stderr, "kiln-soak: error: %s\n", error.c_str());
        return 1;
    }
    log::setMinLevel(log::Level::Error);

    const app::EditableCopy copy(fs::temp_directory_path() / ("kiln-soak-" + std::to_string(getpid())), app::defaultDataRoot());
    const EditedFiles files(copy.root());
    app::Options o;
    app::applyDefaults(o);
    o.headless = true;
    o.width = options->width, o.height = options->height;
    copy.pointAt(o);
    app::App app;
    if (!app.init(o, error)) {
        std::fprintf(stderr, "kiln-soak: error: %s\n", error.c_str());
        return 1;
    }
    app.runtime().readEverything = true;  // every texture is checked, so every output is written
    Soak soak(app, *options, files);
    soak.run();
    const std::vector<std::string> problems = soak.problems();
    soak.printTable();
    for (auto& p : problems) std::printf("kiln-soak: FAIL: %s\n", p.c_str());
    if (problems.empty()) std::printf("kiln-soak: ok\n");
    std::error_code ec;
    fs::create_directories(options->outDir, ec);
    soak.writeJson(fs::path(options->outDir) / "soak.json", problems.empty());
    std::printf("wrote %s/soak.json\n", options->outDir.c_str());
    return problems.empty() ? 0 : 1;
}
