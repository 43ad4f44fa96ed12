// kiln-bench-quality — run time against error for the quality knobs, on the scene that
// is running, frozen at a chosen time. A command, not a test: it prints a table and
// writes CSV.
//
//   kiln-bench-quality [--pipeline FILE] [--also FILE]... [--scene FILE] [--time SECONDS]
//                      [--size WxH] [--spp N] [--frames N] [--repeats R]
//                      [--sweep PASS.PARAM=V1,V2,...]... [--cartesian] [--out DIR] [--cache DIR]
//                      [--region NAME=X0,Y0,Z0,X1,Y1,Z1]...
//
// 1. Steps the scene to --time and freezes it.
// 2. The reference (passes/reference) at --spp paths per pixel, rendered as two
//    independent halves A and B of --spp/2 paths (seeds 1 and 2), each cached as
//    OpenEXR in --cache (default: DIR/cache/) under a hash of the scene file, the
//    simulation's state at --time, the size, the half's path count, its seed and the
//    reference pass's code (progress and ETA on stderr while it renders). The
//    reference is their mean R = (A + B)/2, the same --spp paths as one render.
// 3. The pipeline once as it is ("default"), each --also pipeline as it is (labelled by
//    its file name, e.g. pipelines/course.json: before and after in one run), and once
//    per value of each --sweep (one
//    knob at a time around the default, or every combination with --cartesian; without
//    --sweep, the documented subset below).
//    Per setting: GPU ms per pass (timer queries, medians over --frames with every pass
//    running; then the median over --repeats rounds, each round visiting every setting
//    once, so a slow minute of a shared machine lands on all settings alike, not on
//    the few measured in it), and the errors of composite.hdr (radiance before bloom and tonemap)
//    against the reference: RMSE, relative MSE, SSIM, PSNR; emitters (pixels the
//    G-buffer marks emissive) and the pixels next to them masked out. Also the relative MSE of the indirect part
//    alone (total − direct: the setting run again with composite.indirect_strength 0,
//    the reference's own `direct` output) and per region: in the box floor, walls,
//    ceiling and objects (from the G-buffer depth's world position); in a scene without
//    it, its materials (what each pixel's centre ray meets); and each --region box.
// 4. Bias apart from noise. An error against a path-traced reference includes the
//    reference's own noise: at a few hundred paths relative MSE and SSIM largely
//    measure R, not the setting, and every setting looks about as good. The halves
//    give that noise per pixel, (A − B)²/4 (metrics.hpp), hence:
//    - the reference's noise floor: the relative MSE R has against the truth, on
//      expectation (header; also for the indirect part);
//    - noise-corrected relative MSE, total and indirect: the raw figure less that
//      noise pixel by pixel, an estimate of the error against the converged truth
//      (slightly negative for a setting closer to the truth than R can tell);
//    - bias per region (all, then the regions above), total and indirect: mean
//      luminance of the setting ÷ that of R, ± one standard deviation of R's noise;
//    - SSIM only where it means something: the halves' SSIM against each other is
//      printed; below 0.97 the reference's noise would dominate the structure SSIM
//      sees, so the settings' SSIM is withheld (n/a; empty in the CSV).
// 5. Marks the Pareto front over (total GPU ms, noise-corrected relative MSE): settings
//    no other setting beats on both; plots every setting, the front and the default
//    (DIR/quality.png, log-log: settings at or below 0 are left off). Writes
//    DIR/quality.csv (one row per setting) and DIR/summary.json (the header's figures).
//    The ceiling within 0.5 m of the lamp's axis, where the lamp's near field is, gets
//    its own corrected relMSE beside the reference's noise there, and its bias.
#include <algorithm>
#include <array>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <sstream>

#include "app/app.hpp"
#include "app/context.hpp"
#include "kiln/data_root.hpp"
#include "kiln/hash.hpp"
#include "kiln/image_io.hpp"
#include "kiln/log.hpp"
#include "metrics.hpp"
#include <kiln/plot_script.hpp>
#include "command_line/command_line.hpp"
#include "support/bench_support.hpp"

namespace fs = std::filesystem;
using namespace kiln;
using namespace kiln::bench;

namespace {

// The documented subset swept when no --sweep is given: the knobs the course design's report
// discusses (voxel resolution, aperture, step schedule, trace stride) and the shadow
// filter and map size, the indirect output's size, the lamp's model and its vertices
// or points, the diffuse bounces (the voxels' feedback off: one bounce; the in-frame
// bounces 1–4: --pipeline bench/pipelines/default_before_feedback.json --sweep
// voxel_mip.bounces=1,2,3,4) and how far off their surfaces the voxels gather. The mips, the cone set and the traced lamp change
// bindings or two passes at once, so they are whole pipelines (--also
// pipelines/iso_mips.json, pipelines/normal_cones.json, bench/pipelines/traced_lamp.json;
// sweep cone_trace.cones with --pipeline pipelines/normal_cones.json).
const char* const kDefaultSweeps[] = {
    "voxelize.resolution=32,64,128",
    "cone_trace.aperture=30,45,60,90", "cone_trace.schedule=octave,continuous", "cone_trace.trace_stride=1,2,4",
    "composite.pcf=1,3,5,9",          "shadow.size=512,1024,2048,4096",
    "cone_trace.output_divisor=1,2",  "cone_trace.output_samples=0,240,192", "composite.lamp_samples=8,16,32",
    "voxel_mip.feedback=false,true",  "voxel_mip.gather_diameter_offset=1,1.25,1.5",
    "composite.lamp_model=field,contour,points",
    "shadow.caster_mesh=fine,medium,coarse", "voxelize.tumbler_mode=mesh,splat", "voxelize.lamp_model=field,points",
    "voxelize.transmittance_resolution=8,16,32",
};

struct Args {
    std::string pipeline = (app::defaultDataRoot() / "pipelines/default.json").string();
    std::string scene = (app::defaultDataRoot() / "scenes/cornell.json").string();
    double time = 0.5;
    int width = 128, height = 128, spp = 256, frames = 5, repeats = 3;
    std::vector<std::string> sweeps;
    std::vector<std::string> also;  // more pipelines, measured as they are
    bool cartesian = false;  // every combination of the sweeps, not one knob at a time
    bool images = false;     // write each setting's HDR frame and indirect part beside the reference's
    std::string outDir = "bench-out";
    std::string cacheDir;  // empty: outDir/cache
    std::vector<std::string> regions;  // NAME=X0,Y0,Z0,X1,Y1,Z1: world boxes with figures of their own
};

// A --region: the pixels whose surface lies in a world-space box.
struct WorldRegion {
    std::string name;
    glm::vec3 lo, hi;
};

// NAME=X0,Y0,Z0,X1,Y1,Z1 (either corner first); false with `error` set.
bool parseRegion(const std::string& text, WorldRegion& region, std::string& error) {
    const size_t eq = text.find('=');
    if (eq == 0 || eq == std::string::npos) return error = "expected NAME=X0,Y0,Z0,X1,Y1,Z1, got '" + text + "'", false;
    region.name = text.substr(0, eq);
    float v[6];
    std::istringstream in(text.substr(eq + 1));
    for (int i = 0; i < 6; ++i) {
        char comma = ',';
        if (!(in >> v[i]) || (i < 5 && (!(in >> comma) || comma != ','))) break;
        if (i == 5) {
            in >> std::ws;
            if (!in.eof()) break;
            region.lo = glm::min(glm::vec3(v[0], v[1], v[2]), glm::vec3(v[3], v[4], v[5]));
            region.hi = glm::max(glm::vec3(v[0], v[1], v[2]), glm::vec3(v[3], v[4], v[5]));
            return true;
        }
    }
    return error = region.name + ": expected six numbers X0,Y0,Z0,X1,Y1,Z1 after '=', got '" + text.substr(eq + 1) + "'",
           false;
}

[[noreturn]] void usageError(const std::string& message) {
    std::fprintf(stderr, "kiln-bench-quality: error: %s (see kiln-bench-quality --help)\n", message.c_str());
    std::exit(2);
}

Args parseArgs(int argc, char** argv) {
    Args args;
    CLI::App app{"kiln-bench-quality — run time against error: each setting's frame time and its noise-corrected\n"
                 "error against a path-traced reference (two independent halves); the reference, most of the\n"
                 "run, is cached for the next. Writes OUT/quality.csv and its plot.",
                 "kiln-bench-quality"};
    cli::configure(app);
    // Files are checked here: the reference renders before any pipeline loads, for minutes.
    const CLI::Validator readable(
        [](std::string& path) { return fs::is_regular_file(path) ? std::string() : path + ": cannot read the file"; }, "");
    app.add_option("--pipeline", args.pipeline, "the pipeline measured (default pipelines/default.json)")
        ->type_name("FILE")->check(readable);
    app.add_option("--also", args.also, "another pipeline, measured as it is (repeatable)")
        ->type_name("FILE")->check(readable)->allow_extra_args(false);
    app.add_option("--scene", args.scene, "the scene (default scenes/cornell.json)")->type_name("FILE")->check(readable);
    app.add_option("--time", args.time, "the simulated moment measured, in seconds (default 0.5)")
        ->type_name("S")->check(CLI::Range(0.0, 3600.0));
    cli::addSize(app, "--size", args.width, args.height, 8, 4096, "the picture's size (default 128x128)");
    app.add_option("--spp", args.spp, "reference paths per pixel, an even count: two halves (default 256)")
        ->type_name("N")->check(CLI::Range(2, 1 << 20));
    app.add_option("--frames", args.frames, "timed frames per setting (default 5)")->type_name("N")->check(CLI::Range(1, 1 << 20));
    app.add_option("--repeats", args.repeats, "timing repeats, the median kept (default 3)")->type_name("N")->check(CLI::Range(1, 1 << 20));
    app.add_option("--sweep", args.sweeps, "a knob's values, each measured on its own (repeatable; default: the shipped knobs)")
        ->type_name("PASS.PARAM=V1,V2")->allow_extra_args(false);
    app.add_flag("--cartesian", args.cartesian, "every combination of the sweeps, not one knob at a time");
    app.add_flag("--images", args.images, "also write OUT/images/: each setting's HDR frame and indirect part, and the reference's");
    app.add_option("--out", args.outDir, "where the CSV, plot and images go (default bench-out)")->type_name("DIR");
    app.add_option("--cache", args.cacheDir, "where references are cached (default OUT/cache)")->type_name("DIR");
    app.add_option("--region", args.regions,
                   "a world-space box whose pixels get figures of their own, e.g. dark_room=0,0,-2,4,3,2 (repeatable)")
        ->type_name("NAME=X0,Y0,Z0,X1,Y1,Z1");
    if (const std::optional<int> exitNow = cli::parse(app, argc, argv)) std::exit(*exitNow);
    if (args.spp % 2) std::exit(cli::usageError(app, "--spp " + std::to_string(args.spp) + ": expected an even count (two halves of N/2 paths)"));
    for (const std::string& text : args.regions) {
        WorldRegion region;
        std::string error;
        if (!parseRegion(text, region, error)) usageError("--region " + error);
    }
    if (args.sweeps.empty()) args.sweeps.assign(std::begin(kDefaultSweeps), std::end(kDefaultSweeps));
    return args;
}

struct Setting {
    std::string label;
    std::vector<Override> overrides;
    std::string pipeline;  // empty: --pipeline
};

// The default, then either each sweep's values one knob at a time, or (--cartesian)
// every combination of them.
std::vector<Setting> settingsOf(const Args& args) {
    std::vector<std::vector<Setting>> axes;
    for (auto& sweep : args.sweeps) {
        Override base;
        std::string error;
        if (!parseOverride(sweep, base, error)) usageError("--sweep " + error);
        std::stringstream values(base.json);
        std::string v;
        axes.emplace_back();
        while (std::getline(values, v, ','))
            axes.back().push_back({base.pass + "." + base.param + "=" + v, {{base.pass, base.param, v}}});
    }
    std::vector<Setting> settings{{"default", {}}};
    for (auto& file : args.also) settings.push_back({fs::path(file).stem().string(), {}, file});
    if (!args.cartesian) {
        for (auto& axis : axes) settings.insert(settings.end(), axis.begin(), axis.end());
        return settings;
    }
    std::vector<Setting> product{{"", {}}};
    for (auto& axis : axes) {
        std::vector<Setting> next;
        for (auto& p : product)
            for (auto& value : axis) {
                Setting s{p.label.empty() ? value.label : p.label + " " + value.label, p.overrides};
                s.overrides.insert(s.overrides.end(), value.overrides.begin(), value.overrides.end());
                next.push_back(std::move(s));
            }
        product = std::move(next);
        if (product.size() > 4096) usageError("--cartesian: more than 4096 combinations");
    }
    settings.insert(settings.end(), product.begin(), product.end());
    return settings;
}

bool fail(const std::string& message) {
    std::fprintf(stderr, "kiln-bench-quality: error: %s\n", message.c_str());
    return false;
}

// The reference is rendered as two halves with these seeds (independent random
// sequences: the path tracer hashes the seed into every pixel's stream).
constexpr int kHalfSeeds[2] = {1, 2};
// The halves' SSIM against each other below which the settings' SSIM is withheld.
constexpr double kSsimMeaningful = 0.97;

// The reference as two independent halves and their mean; each also as its indirect
// part (radiance − direct), which is what the indirect figures compare.
struct Reference {
    FloatImage halves[2], halvesIndirect[2], halvesDirect[2];
    FloatImage mean, meanIndirect;  // R = (A + B)/2: what the errors are measured against
    double renderSeconds = 0;       // rendering this run (0: both from the cache)
    double renderedRays = 0;        // the rays those renders traced (reference.rays summed)
};

// One half of the reference (radiance and direct), from the cache or rendered now.
// The cache key covers everything the image depends on: the scene file (looks, lamp),
// the simulation's state at --time (so a change to the simulation's code is a new
// reference), the size, the half's path count and seed, and the reference pass's code:
// its shaders, the shared ones it includes and its module's source.
bool referenceHalf(app::App& app, const Args& args, int half, FloatImage& out, FloatImage& direct, double& seconds,
                   double& rays) {
    const int seed = kHalfSeeds[half], paths = args.spp / 2;
    const std::string sceneText = slurp(args.scene);
    uint64_t key = fnv1a(sceneText);
    const double values[] = {args.time, double(args.width), double(args.height), double(paths), double(seed)};
    key = fnv1a(values, sizeof values, key);
    const uint64_t simState = app.scene().sim().stateHash();
    key = fnv1a(&simState, sizeof simState, key);
    // The reference's code: its module's source (an installed Kiln has the module instead)
    // and the files its shader reads, includes followed. Only those: an edit to a shared
    // include the reference does not read (composite's shadows) keeps the cache.
    const fs::path source(KILN_SOURCE_DIR);
    std::vector<fs::path> code = {fs::exists(source / "passes/reference/reference.cpp")
                                      ? source / "passes/reference/reference.cpp"
                                      : shippedFiles().modules / "libpass_reference.so"};
    PreprocessedSource shader;
    ShaderError shaderError;
    if (!app.runtime().shaders().preprocess("reference/path.comp", {}, shader, shaderError)) {
        std::fprintf(stderr, "kiln-bench-quality: error: %s\n", shaderError.toString().c_str());
        return false;
    }
    code.insert(code.end(), shader.dependencies.begin(), shader.dependencies.end());
    std::sort(code.begin(), code.end());
    for (const fs::path& file : code) key = fnv1a(slurp(file.string()), key);
    char name[80];
    std::snprintf(name, sizeof name, "reference-%016llx-seed%d.exr", static_cast<unsigned long long>(key), seed);
    const fs::path cache = (args.cacheDir.empty() ? fs::path(args.outDir) / "cache" : fs::path(args.cacheDir)) / name;
    fs::path directCache = cache;
    directCache.replace_extension(".direct.exr");
    char what[64];
    std::snprintf(what, sizeof what, "reference half %c (seed %d)", "AB"[half], seed);
    std::string error;
    if (fs::exists(cache) && fs::exists(directCache) && readExr(cache.string(), out, error) &&
        readExr(directCache.string(), direct, error)) {
        std::printf("%s: %s (cached)\n", what, cache.string().c_str());
        return true;
    }
    const int perFrame = std::min(paths, 16);
    const std::string text = R"({"output": "reference.radiance", "passes": [{"id": "reference", "module": "reference",
        "params": {"samples_per_frame": )" + std::to_string(perFrame) + R"(, "max_samples": )" + std::to_string(paths) +
                             R"(, "seed": )" + std::to_string(seed) + "}}]}";
    if (!app.runtime().loadPipelineText(text, "reference", error)) return fail(error);
    const auto start = std::chrono::steady_clock::now();
    // Until the first and the last row have every path: a frame stops at the pass's time
    // budget, so how many frames that takes depends on the scene and the machine. (The
    // first row is one pass ahead of the last while a pass is under way; until the last
    // row is overwritten it may still hold the previous half's count.)
    for (int now = 0; now < paths;) {
        app.frame();
        const TextureRef* t = app.runtime().findTexture("reference", "radiance");
        if (!t) return fail("the reference pass produced no texture");
        float first[4] = {}, last[4] = {};
        glGetTextureSubImage(t->id, 0, 0, 0, 0, 1, 1, 1, GL_RGBA, GL_FLOAT, sizeof first, first);
        glGetTextureSubImage(t->id, 0, t->width - 1, t->height - 1, 0, 1, 1, 1, GL_RGBA, GL_FLOAT, sizeof last, last);
        now = int(std::min(first[3], last[3]));
        if (!app.runtime().activeErrors().empty()) return fail(app.runtime().activeErrors().front());
        const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        const int bar = 30 * now / paths;
        std::fprintf(stderr, "\r%s %dx%d [%-30s] %d/%d paths/px, %.0f s, ETA %.0f s ", what, args.width, args.height,
                     std::string(size_t(bar), '#').c_str(), now, paths, elapsed,
                     now > 0 ? elapsed / now * (paths - now) : 0.0);
    }
    std::fprintf(stderr, "\n");
    const TextureRef* t = app.runtime().findTexture("reference", "radiance");
    if (!t) return fail("the reference pass produced no texture");
    out = readTexture(t->id, t->target, t->format, t->width, t->height);
    const TextureRef* d = app.runtime().findTexture("reference", "direct");
    if (!d) return fail("the reference pass produced no direct texture");
    direct = readTexture(d->id, d->target, d->format, d->width, d->height);
    if (out.at(0, 0)[3] != float(paths)) return fail("the reference stopped early: " + std::to_string(out.at(0, 0)[3]) + " paths");
    fs::create_directories(cache.parent_path());
    if (!writeExr(cache.string(), out, error) || !writeExr(directCache.string(), direct, error)) return fail(error);
    seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    const TextureRef* r = app.runtime().findTexture("reference", "rays");
    if (!r) return fail("the reference pass produced no rays texture");
    const FloatImage perPixel = readTexture(r->id, r->target, r->format, r->width, r->height);
    rays = 0;
    for (int y = 0; y < perPixel.height; ++y)
        for (int x = 0; x < perPixel.width; ++x) rays += perPixel.at(x, y)[0];
    const double pathCount = double(paths) * args.width * args.height;
    std::printf("%s: %d paths/px in %.1f s (%.0f k paths/s, %.2f M rays/s, %.1f rays a path), cached as %s\n", what,
                paths, seconds, pathCount / seconds / 1000.0, rays / seconds / 1e6, rays / pathCount,
                cache.string().c_str());
    return true;
}

bool loadReference(app::App& app, const Args& args, Reference& ref) {
    for (int half = 0; half < 2; ++half) {
        double seconds = 0, rays = 0;
        if (!referenceHalf(app, args, half, ref.halves[half], ref.halvesDirect[half], seconds, rays)) return false;
        ref.renderSeconds += seconds;
        ref.renderedRays += rays;
        ref.halvesIndirect[half] = metrics::difference(ref.halves[half], ref.halvesDirect[half]);
    }
    ref.mean = metrics::average(ref.halves[0], ref.halves[1]);
    ref.meanIndirect = metrics::average(ref.halvesIndirect[0], ref.halvesIndirect[1]);
    return true;
}

// The parts of the picture the figures are given for, each a mask over the counted
// pixels: "all", the scene's regions (each pixel in at most one), then the --region
// boxes (which may overlap them and each other). In the box: floor, walls, ceiling and
// objects, from the world position of the G-buffer's depth. A scene without the box:
// its materials, by what each pixel's centre ray meets first (the CPU walk of the
// reference's BVH), the eight that cover most of the picture named, the rest together.
struct Parts {
    std::vector<std::string> names;
    std::vector<metrics::Mask> masks;
    metrics::Mask domeRing;   // the ceiling within 0.5 m of the lamp's axis (box scenes)
};

constexpr int kMaterialRegions = 8;
constexpr double kMaterialRegionShare = 0.02;  // of the drawn pixels, to be named

Parts partsOf(app::App& app, const Args& args, const FloatImage& depth, const metrics::Mask& counted) {
    const size_t pixels = size_t(depth.width) * depth.height;
    const glm::mat4 invViewProj = glm::inverse(app.camera().projection(float(depth.width) / float(depth.height)) *
                                               app.camera().view());
    auto unproject = [&](int x, int y, float ndcZ) {
        glm::vec4 p = invViewProj * glm::vec4((x + 0.5f) / depth.width * 2 - 1, (y + 0.5f) / depth.height * 2 - 1, ndcZ, 1);
        return glm::vec3(p) / p.w;
    };
    Parts parts;
    parts.domeRing.assign(pixels, 0);
    std::vector<int> region(pixels, -1);
    std::vector<std::string> names;
    if (app.scene().look().walls) {
        names = {"floor", "walls", "ceiling", "objects"};
        const glm::vec2 lampAxis(app.scene().look().lampCentre.x, app.scene().look().lampCentre.z);
        constexpr float kOnWall = 0.995f;  // within 5 mm of a wall plane
        for (int y = 0; y < depth.height; ++y)
            for (int x = 0; x < depth.width; ++x) {
                const float d = depth.at(x, y)[0];
                if (d >= 1.0f) continue;  // nothing drawn
                const glm::vec3 p = unproject(x, y, d * 2 - 1);
                const size_t i = size_t(y) * depth.width + x;
                int r = 3;
                if (p.y < -kOnWall) r = 0;
                else if (p.y > kOnWall) {
                    r = 2;
                    parts.domeRing[i] = glm::distance(glm::vec2(p.x, p.z), lampAxis) < 0.5f;
                }
                else if (std::abs(p.x) > kOnWall || p.z < -kOnWall) r = 1;
                region[i] = r;
            }
    } else {
        const ray::RayMeshData& rays = app.renderer().rayMeshData();
        std::map<std::string, int> index;
        std::vector<std::string> seen;
        std::vector<size_t> count;
        size_t drawn = 0;
        for (int y = 0; y < depth.height; ++y)
            for (int x = 0; x < depth.width; ++x) {
                if (depth.at(x, y)[0] >= 1.0f) continue;
                ++drawn;
                const glm::vec3 o = unproject(x, y, -1.0f);
                const ray::RayHit hit = rays.nearestHit(o, unproject(x, y, 1.0f) - o);
                if (!hit.found()) continue;
                const std::string name = app.renderer().materialNameOf(rays.instances()[hit.instance].instance);
                auto [it, added] = index.try_emplace(name, int(seen.size()));
                if (added) seen.push_back(name), count.push_back(0);
                ++count[size_t(it->second)];
                region[size_t(y) * depth.width + x] = it->second;
            }
        std::vector<int> byCount(seen.size());
        for (size_t k = 0; k < byCount.size(); ++k) byCount[k] = int(k);
        std::stable_sort(byCount.begin(), byCount.end(), [&](int a, int b) { return count[size_t(a)] > count[size_t(b)]; });
        std::vector<int> renamed(seen.size(), -1);
        bool rest = false;
        for (int k : byCount) {
            if (int(names.size()) < kMaterialRegions && count[size_t(k)] >= kMaterialRegionShare * double(drawn)) {
                renamed[size_t(k)] = int(names.size());
                names.push_back(seen[size_t(k)]);
            } else {
                rest = true;
            }
        }
        const int restIndex = int(names.size());
        if (rest) names.push_back("other materials");
        for (int& r : region)
            if (r >= 0) r = renamed[size_t(r)] >= 0 ? renamed[size_t(r)] : restIndex;
    }
    parts.names.push_back("all");
    parts.masks.push_back(counted);
    for (size_t k = 0; k < names.size(); ++k) {
        metrics::Mask m = counted;
        for (size_t i = 0; i < pixels; ++i) m[i] = m[i] && region[i] == int(k);
        parts.names.push_back(names[k]);
        parts.masks.push_back(std::move(m));
    }
    for (const std::string& text : args.regions) {
        WorldRegion box;
        std::string error;
        parseRegion(text, box, error);  // checked with the arguments
        metrics::Mask m(pixels, 0);
        for (int y = 0; y < depth.height; ++y)
            for (int x = 0; x < depth.width; ++x) {
                const size_t i = size_t(y) * depth.width + x;
                const float d = depth.at(x, y)[0];
                if (d >= 1.0f || !counted[i]) continue;
                const glm::vec3 p = unproject(x, y, d * 2 - 1);
                m[i] = glm::all(glm::greaterThanEqual(p, box.lo)) && glm::all(glm::lessThanEqual(p, box.hi));
            }
        parts.names.push_back(box.name);
        parts.masks.push_back(std::move(m));
    }
    for (size_t i = 0; i < pixels; ++i) parts.domeRing[i] = parts.domeRing[i] && counted[i];
    return parts;
}

struct Result {
    std::string label;
    std::vector<std::pair<std::string, double>> passMs;  // plan order
    double totalMs = 0;
    metrics::Errors errors;  // against R
    double indirectRelMse = 0;
    std::vector<std::string> partNames;  // Parts::names
    std::vector<double> partRelMse;      // per part, against R
    // Less the reference's own noise: estimates of the error against the truth.
    double relMseCorrected = 0, indirectRelMseCorrected = 0;
    // Mean luminance of the setting ÷ that of R, total, indirect and direct, per part.
    std::vector<metrics::RatioWithUncertainty> meanRatio, indirectRatio, directRatio;
    // The ceiling around the dome: corrected relMSE, the reference's own noise there, bias.
    double ringRelMseCorrected = 0, ringNoise = 0;
    int ringPixels = 0;
    metrics::RatioWithUncertainty ringRatio;
    metrics::Mask counted;  // the pixels the figures count (emitters out)
    bool pareto = false;
};

// Every pixel counted but those showing an emitter (nonzero G-buffer emission) and
// those next to one: the reference integrates over each pixel's area, so a pixel on an
// emitter's edge holds part of its glow, which a rasterizer sampling pixel centres does
// not (the ceiling beside the dome read 0.82x the reference's light with them).
metrics::Mask emittersMasked(const FloatImage& glow) {
    auto glows = [&](int x, int y) {
        if (x < 0 || y < 0 || x >= glow.width || y >= glow.height) return false;
        const float* e = glow.at(x, y);
        return e[0] + e[1] + e[2] > 0.0f;
    };
    metrics::Mask mask(size_t(glow.width) * glow.height, 1);
    for (int y = 0; y < glow.height; ++y)
        for (int x = 0; x < glow.width; ++x)
            for (int dy = -1; dy <= 1; ++dy)
                for (int dx = -1; dx <= 1; ++dx)
                    if (glows(x + dx, y + dy)) mask[size_t(y) * glow.width + x] = 0;
    return mask;
}

// The ceiling around the dome: its pixels, corrected relMSE, the reference's noise there
// and the mean light over the reference's.
void domeRingFigures(const FloatImage& image, const Reference& ref, const metrics::Mask& ring, Result& r) {
    r.ringPixels = int(std::count(ring.begin(), ring.end(), 1));
    if (r.ringPixels == 0) return;
    r.ringRelMseCorrected = metrics::noiseCorrectedRelativeMse(image, ref.halves[0], ref.halves[1], ring);
    r.ringNoise = metrics::referenceNoiseRelativeMse(ref.halves[0], ref.halves[1], ring);
    r.ringRatio = metrics::meanLuminanceRatio(image, ref.halves[0], ref.halves[1], ring);
}

// The indirect part's errors and bias per region (image less the frame without it), and
// the direct part's bias (the frame without it: the lamp's light and what is seen glowing).
void indirectFigures(const FloatImage& indirect, const FloatImage& direct, const Reference& ref,
                     const metrics::Mask& mask, const std::vector<metrics::Mask>& partMask, Result& r) {
    r.indirectRatio.resize(partMask.size());
    r.directRatio.resize(partMask.size());
    const FloatImage& indirectA = ref.halvesIndirect[0];
    const FloatImage& indirectB = ref.halvesIndirect[1];
    r.indirectRelMse = metrics::relativeMse(indirect, ref.meanIndirect, mask);
    r.indirectRelMseCorrected = metrics::noiseCorrectedRelativeMse(indirect, indirectA, indirectB, mask);
    for (size_t p = 0; p < partMask.size(); ++p)
        r.indirectRatio[p] = metrics::meanLuminanceRatio(indirect, indirectA, indirectB, partMask[p]);
    for (size_t p = 0; p < partMask.size(); ++p)
        r.directRatio[p] = metrics::meanLuminanceRatio(direct, ref.halvesDirect[0], ref.halvesDirect[1], partMask[p]);
}

// --images: OUT/images/LABEL.exr and LABEL.indirect.exr ('/' in a label becomes '_').
bool writeImages(const Args& args, const std::string& label, const FloatImage& image, const FloatImage& indirect) {
    const fs::path dir = fs::path(args.outDir) / "images";
    std::error_code ec;
    fs::create_directories(dir, ec);
    std::string name = label;
    std::replace(name.begin(), name.end(), '/', '_');
    std::string error;
    if (!writeExr((dir / (name + ".exr")).string(), image, error) ||
        !writeExr((dir / (name + ".indirect.exr")).string(), indirect, error))
        return fail(label + ": " + error);
    return true;
}

bool score(app::App& app, const Args& args, const std::string& label, const Reference& ref, std::optional<Parts>& parts,
           Result& r);

bool measure(app::App& app, const Args& args, const Setting& setting, const Reference& ref, std::optional<Parts>& parts,
             Result& r) {
    std::string text, error;
    const std::string& pipeline = setting.pipeline.empty() ? args.pipeline : setting.pipeline;
    if (!applyOverrides(slurp(pipeline), setting.overrides, text, error) ||
        !app.runtime().loadPipelineText(text, pipeline, error))
        return fail(setting.label + ": " + error);
    app.runtime().setRequested({"composite.hdr", "gbuffer.emissive", "gbuffer.depth"});
    app.runtime().alwaysRun = true;
    // Compile, allocate, and let what converges over frames settle (as many frames as
    // the passes ask for with keepRunning: voxel_mip's feedback 16 after a change).
    for (int f = 0; f < 2; ++f) app.frame();
    app.settle();
    glFinish();
    app.runtime().resetTimings();
    for (int f = 0; f < args.frames; ++f) app.frame();
    glFinish();
    return score(app, args, setting.label, ref, parts, r);
}

// The errors of the frame the pipeline just rendered, and the GPU times of the frames
// since the last resetTimings.
// `parts`: found at the first setting scored and kept (every setting shows one scene from
// one camera, with the same emitters masked).
bool score(app::App& app, const Args& args, const std::string& label, const Reference& ref, std::optional<Parts>& parts,
           Result& r) {
    std::string error;
    app.runtime().collectGpuTimes();
    for (auto& errorText : app.runtime().activeErrors()) return fail(label + ": " + errorText);
    r.label = label;
    for (auto& row : app.runtime().stats()) {
        if (row.ranFrames == 0) continue;
        r.passMs.emplace_back(row.id, row.gpuMedianMs);
        r.totalMs += row.gpuMedianMs;
    }
    const TextureRef* hdr = app.runtime().findTexture("composite", "hdr");
    const TextureRef* emissive = app.runtime().findTexture("gbuffer", "emissive");
    if (!hdr || !emissive) return fail(label + ": the pipeline has no composite.hdr / gbuffer.emissive");
    const FloatImage image = readTexture(hdr->id, hdr->target, hdr->format, hdr->width, hdr->height);
    const metrics::Mask mask =
        emittersMasked(readTexture(emissive->id, emissive->target, emissive->format, emissive->width, emissive->height));
    const FloatImage& halfA = ref.halves[0];
    const FloatImage& halfB = ref.halves[1];
    r.errors = metrics::compare(image, ref.mean, mask);
    r.relMseCorrected = metrics::noiseCorrectedRelativeMse(image, halfA, halfB, mask);

    if (!parts) {
        const TextureRef* depth = app.runtime().findTexture("gbuffer", "depth");
        if (!depth) return fail(label + ": the pipeline has no gbuffer.depth");
        parts = partsOf(app, args, readTexture(depth->id, depth->target, depth->format, depth->width, depth->height), mask);
    }
    domeRingFigures(image, ref, parts->domeRing, r);
    const std::vector<metrics::Mask>& partMask = parts->masks;
    r.partNames = parts->names;
    r.meanRatio.resize(partMask.size());
    for (size_t p = 0; p < partMask.size(); ++p) {
        r.partRelMse.push_back(metrics::relativeMse(image, ref.mean, partMask[p]));
        r.meanRatio[p] = metrics::meanLuminanceRatio(image, halfA, halfB, partMask[p]);
    }
    // The indirect part: the same frame without composite's indirect term.
    if (!app.runtime().setParam("composite", "indirect_strength", 0.0f, error)) return fail(label + ": " + error);
    app.frame();
    glFinish();
    const FloatImage direct = readTexture(hdr->id, hdr->target, hdr->format, hdr->width, hdr->height);
    const FloatImage indirect = metrics::difference(image, direct);
    indirectFigures(indirect, direct, ref, mask, partMask, r);
    if (args.images && !writeImages(args, label, image, indirect)) return false;
    r.counted = mask;
    // The ratios may be NaN (a region out of view): they are printed as n/a, not checked.
    for (double v : {r.errors.rmse, r.errors.relMse, r.errors.ssim, r.relMseCorrected, r.indirectRelMse, r.indirectRelMseCorrected})
        if (!std::isfinite(v)) return fail(label + ": an error metric is not finite");
    return true;
}

// The default pipeline while the scene moves: the simulation restarted and stepped to
// --time with the pipeline rendering every step as the window does (passes skip what
// did not change; feedback is as many frames behind as it is in use), the frame at
// --time scored against the same reference. A frozen frame cannot show what lags
// behind motion; this row can. GPU times: the last --frames frames before --time.
// False (said on stderr) when it fails or the simulation does not reach the state
// the reference was rendered from.
bool measureMoving(app::App& app, const Args& args, const Reference& ref, std::optional<Parts>& parts, Result& r) {
    const uint64_t frozenState = app.scene().sim().stateHash();
    std::string text = slurp(args.pipeline), error;
    if (!app.runtime().loadPipelineText(text, args.pipeline, error)) return fail(args.pipeline + ": " + error);
    app.runtime().setRequested({"composite.hdr", "gbuffer.emissive", "gbuffer.depth"});
    app.runtime().alwaysRun = false;
    app.scene().reset();
    app.paused = false;
    app.frame();
    const double dt = app.scene().time();
    bool timing = false;
    while (app.scene().time() + 1e-9 < args.time) {
        if (!timing && app.scene().time() + dt * args.frames + 1e-9 >= args.time) {
            glFinish();
            app.runtime().resetTimings();
            timing = true;
        }
        app.frame();
    }
    glFinish();
    app.paused = true;
    if (app.scene().sim().stateHash() != frozenState)
        return fail("the moving run reached t = " + std::to_string(app.scene().time()) +
                    " in another state than the frozen frame's (is the simulation deterministic?)");
    const std::string label = fs::path(args.pipeline).stem().string() + " (moving)";
    return score(app, args, label, ref, parts, r);
}

void markPareto(std::vector<Result>& results) {
    for (auto& a : results) {
        a.pareto = true;
        for (auto& b : results)
            if (&a != &b && b.totalMs <= a.totalMs && b.relMseCorrected <= a.relMseCorrected &&
                (b.totalMs < a.totalMs || b.relMseCorrected < a.relMseCorrected))
                a.pareto = false;
    }
}

// A ratio and its uncertainty in 12 columns ("1.023±0.004"), or n/a (a part out of view).
std::string ratioCell(const metrics::RatioWithUncertainty& r) {
    char cell[48];
    if (std::isfinite(r.ratio)) std::snprintf(cell, sizeof cell, "%6.3f±%5.3f", r.ratio, r.uncertainty);
    else std::snprintf(cell, sizeof cell, "%12s", "n/a");
    return cell;
}

// A CSV cell: empty where there is no value (NaN), so a reader sees a gap, not "nan".
std::string csvNumber(double v) {
    if (!std::isfinite(v)) return "";
    std::ostringstream s;
    s << v;
    return s.str();
}

// Every setting in rounds (interleaved, so a slow spell of the machine hits them all):
// errors from the first round (they are deterministic), times the medians of the rounds;
// the Pareto front marked. False (said on stderr) when a setting fails.
bool measureAll(app::App& app, const Args& args, const std::vector<Setting>& settings, const Reference& ref,
                std::optional<Parts>& parts, std::vector<Result>& results) {
    results.assign(settings.size(), Result{});
    std::vector<std::map<std::string, std::vector<double>>> passSamples(settings.size());
    std::vector<std::vector<double>> totals(settings.size());
    cli::Progress progress("settings measured", args.repeats * int(settings.size()));
    for (int round = 0; round < args.repeats; ++round)
        for (size_t i = 0; i < settings.size(); ++i) {
            Result r;
            if (!measure(app, args, settings[i], ref, parts, r)) return false;
            progress.advance(round * int(settings.size()) + int(i) + 1);
            totals[i].push_back(r.totalMs);
            for (auto& [id, ms] : r.passMs) passSamples[i][id].push_back(ms);
            if (round == 0) results[i] = std::move(r);
        }
    for (size_t i = 0; i < settings.size(); ++i) {
        results[i].totalMs = median(totals[i]);
        for (auto& [id, ms] : results[i].passMs) ms = median(passSamples[i][id]);
    }
    markPareto(results);
    return true;
}

// The reference's own figures, over the pixels the first setting counts (every
// pipeline draws the same scene from the same camera, so the emitters are the same).
struct ReferenceFigures {
    double halvesSsim = 0, noiseFloor = 0, noiseFloorIndirect = 0;
    bool ssimMeaningful = false;
};

ReferenceFigures referenceFigures(const Reference& ref, const Args& args, const metrics::Mask& counted) {
    ReferenceFigures f;
    f.halvesSsim = metrics::ssim(metrics::displayLuminance(ref.halves[0]), metrics::displayLuminance(ref.halves[1]),
                                 args.width, args.height, counted);
    f.ssimMeaningful = f.halvesSsim >= kSsimMeaningful;
    f.noiseFloor = metrics::referenceNoiseRelativeMse(ref.halves[0], ref.halves[1], counted);
    f.noiseFloorIndirect = metrics::referenceNoiseRelativeMse(ref.halvesIndirect[0], ref.halvesIndirect[1], counted);
    std::printf("\nreference noise floor: relMSE %.5f, indirect %.5f (R's own error against the truth, on expectation;\n"
                "  the \"corrected\" columns subtract it pixel by pixel: estimates of the error against the truth)\n",
                f.noiseFloor, f.noiseFloorIndirect);
    std::printf("reference halves: SSIM(A, B) = %.4f (display luminance, emitters masked)\n", f.halvesSsim);
    if (!f.ssimMeaningful)
        std::printf("SSIM withheld: the reference's halves score %.4f against each other (< %.2f); more --spp\n",
                    f.halvesSsim, kSsimMeaningful);
    std::printf("\n");
    return f;
}

// The error table on stdout and quality.csv, one row per setting each.
// A part's name as a CSV column's: lower case, what is not a letter or digit '_'.
std::string columnName(const std::string& name) {
    std::string c;
    for (char ch : name) c += std::isalnum(static_cast<unsigned char>(ch)) ? char(std::tolower(static_cast<unsigned char>(ch))) : '_';
    return c;
}

void writeErrors(const std::vector<Result>& results, bool ssimMeaningful, const std::string& csvPath) {
    std::ofstream csv(csvPath);
    const std::vector<std::string>& partNames = results.front().partNames;
    csv << "setting,total_gpu_ms,rmse,rel_mse,ssim,psnr,pixels,pareto,rel_mse_indirect";
    for (size_t p = 1; p < partNames.size(); ++p) csv << ",rel_mse_" << columnName(partNames[p]);
    csv << ",rel_mse_corrected,rel_mse_indirect_corrected";
    for (const char* kind : {"mean_ratio_", "indirect_ratio_"})
        for (const std::string& name : partNames) {
            const std::string part = columnName(name);
            csv << ',' << kind << part << ',' << kind << part << "_uncertainty";
        }
    csv << ",dome_ring_pixels,rel_mse_dome_ring_corrected,ref_noise_dome_ring,mean_ratio_dome_ring,"
           "mean_ratio_dome_ring_uncertainty,pass_ms";
    for (const std::string& name : partNames)
        csv << ",direct_ratio_" << columnName(name) << ",direct_ratio_" << columnName(name) << "_uncertainty";
    csv << '\n';
    std::string regionsHeading = "relMSE";
    for (size_t p = 1; p < partNames.size(); ++p) regionsHeading += (p == 1 ? " " : "/") + partNames[p];
    std::printf("%-44s %9s %9s %9s %9s %7s %7s %9s %9s %s  %s\n", "setting", "gpu ms", "RMSE", "relMSE", "corrected",
                "SSIM", "PSNR", "indirect", "corrected", "front", regionsHeading.c_str());
    for (const Result& r : results) {
        char ssimCell[16] = "n/a";
        if (ssimMeaningful) std::snprintf(ssimCell, sizeof ssimCell, "%.4f", r.errors.ssim);
        std::printf("%-44s %9.2f %9.5f %9.5f %9.5f %7s %7.2f %9.5f %9.5f %5s ", r.label.c_str(), r.totalMs,
                    r.errors.rmse, r.errors.relMse, r.relMseCorrected, ssimCell, r.errors.psnr, r.indirectRelMse,
                    r.indirectRelMseCorrected, r.pareto ? "*" : "");
        for (size_t p = 1; p < r.partRelMse.size(); ++p) std::printf(" %7.4f", r.partRelMse[p]);
        std::printf("\n");
        std::string passes;
        for (auto& [id, ms] : r.passMs) passes += (passes.empty() ? "" : " ") + id + "=" + std::to_string(ms);
        csv << '"' << r.label << "\"," << r.totalMs << ',' << r.errors.rmse << ',' << r.errors.relMse << ','
            << (ssimMeaningful ? csvNumber(r.errors.ssim) : "") << ',' << r.errors.psnr << ',' << r.errors.pixels << ','
            << (r.pareto ? 1 : 0) << ',' << r.indirectRelMse;
        for (size_t p = 1; p < r.partRelMse.size(); ++p) csv << ',' << csvNumber(r.partRelMse[p]);
        csv << ',' << r.relMseCorrected << ',' << r.indirectRelMseCorrected;
        for (const auto* ratios : {&r.meanRatio, &r.indirectRatio})
            for (const metrics::RatioWithUncertainty& ratio : *ratios)
                csv << ',' << csvNumber(ratio.ratio) << ',' << csvNumber(ratio.uncertainty);
        csv << ',' << r.ringPixels << ',' << r.ringRelMseCorrected << ',' << r.ringNoise << ','
            << csvNumber(r.ringRatio.ratio) << ',' << csvNumber(r.ringRatio.uncertainty);
        csv << ",\"" << passes << '"';
        for (const metrics::RatioWithUncertainty& ratio : r.directRatio)
            csv << ',' << csvNumber(ratio.ratio) << ',' << csvNumber(ratio.uncertainty);
        csv << '\n';
    }
    std::printf("\n* = on the Pareto front of (GPU ms, corrected relMSE); corrected = less the reference's own noise\n\n");
}

// The bias table (mean light over the reference's, per region, total and indirect) and
// the ceiling around the dome.
void printBias(const std::vector<Result>& results) {
    std::printf("bias: mean luminance of the setting ÷ the reference's, ± 1σ of the reference's noise\n");
    const std::vector<std::string>& partNames = results.front().partNames;
    std::vector<int> widths;
    for (const std::string& name : partNames) widths.push_back(std::max(12, int(name.size())));
    for (const char* kind : {"total", "indirect"}) {
        std::printf("\n%-44s", kind);
        for (size_t p = 0; p < partNames.size(); ++p) std::printf(" %*s", widths[p], partNames[p].c_str());
        std::printf("\n");
        for (const Result& r : results) {
            const auto& ratios = std::string(kind) == "total" ? r.meanRatio : r.indirectRatio;
            std::printf("%-44s", r.label.c_str());
            for (size_t p = 0; p < ratios.size(); ++p) std::printf(" %*s", widths[p], ratioCell(ratios[p]).c_str());
            std::printf("\n");
        }
    }
    if (!results.empty() && results.front().ringPixels > 0) {
        std::printf("\nthe ceiling within 0.5 m of the lamp's axis (%d px; the reference's own relMSE there %.5f):\n",
                    results.front().ringPixels, results.front().ringNoise);
        std::printf("%-44s %12s %14s\n", "setting", "corrected", "mean light");
        for (const Result& r : results)
            std::printf("%-44s %12.5f %14s\n", r.label.c_str(), r.ringRelMseCorrected, ratioCell(r.ringRatio).c_str());
    }

}

// The run's header: what was measured, the reference's figures, how long it took.
// null where a figure has no value (nlohmann writes NaN as null).
nlohmann::json summary(const Args& args, const std::string& device, double sceneTime, const std::vector<Result>& results,
                       const ReferenceFigures& figures, const Reference& ref,
                       std::chrono::steady_clock::time_point started) {
    return {
        {"device", device},
        {"scene", args.scene},
        {"scene_time_s", sceneTime},
        {"width", args.width},
        {"height", args.height},
        {"spp", args.spp},
        {"spp_per_half", args.spp / 2},
        {"seeds", {kHalfSeeds[0], kHalfSeeds[1]}},
        {"pixels", results.front().errors.pixels},
        {"ssim_halves", figures.halvesSsim},
        {"ssim_threshold", kSsimMeaningful},
        {"ssim_reported", figures.ssimMeaningful},
        {"ref_noise_rel_mse", figures.noiseFloor},
        {"ref_noise_rel_mse_indirect", figures.noiseFloorIndirect},
        {"reference_render_s", ref.renderSeconds},
        {"reference_rays_per_s", ref.renderSeconds > 0 ? ref.renderedRays / ref.renderSeconds : NAN},
        {"wall_s", std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count()},
        {"frames", args.frames},
        {"repeats", args.repeats},
        {"settings", results.size()},
    };
}

bool plotQuality(const Args& args, const std::string& device, const std::string& csvPath, const std::string& pngPath,
                 std::string& error) {
    std::vector<std::string> plotArgs{"quality", csvPath, pngPath};
    for (auto& also : args.also) plotArgs.insert(plotArgs.end(), {"--highlight", fs::path(also).stem().string()});
    plotArgs.insert(plotArgs.end(), {"--about", kiln::plotAbout(args.width, args.height, device)});
    return kiln::drawPlot(plotArgs, error);
}

}  // namespace

int main(int argc, char** argv) {
    const auto started = std::chrono::steady_clock::now();
    const Args args = parseArgs(argc, argv);
    const std::vector<Setting> settings = settingsOf(args);
    std::string error;
    auto context = app::HeadlessContext::create(false, error);
    if (!context) return fail(error) ? 0 : 1;
    log::setMinLevel(log::Level::Warn);

    app::Options o;
    app::applyDefaults(o);
    o.headless = true;
    o.live = false;
    o.width = args.width;
    o.height = args.height;
    o.scene = args.scene;
    o.pipeline = args.pipeline;
    app::App app;
    if (!app.init(o, error)) return fail(error) ? 0 : 1;
    while (app.scene().time() + 1e-9 < args.time) app.frame();  // to the chosen moment
    app.paused = true;
    std::printf("device: %s\nscene %s frozen at t = %.3f s, %dx%d, reference %d paths/px (two halves of %d, seeds %d and %d), "
                "%d timed frames x %d rounds\n\n",
                context->description().c_str(), args.scene.c_str(), app.scene().time(), args.width, args.height,
                args.spp, args.spp / 2, kHalfSeeds[0], kHalfSeeds[1], args.frames, args.repeats);

    Reference ref;
    if (!loadReference(app, args, ref)) return 1;
    if (args.images && (!writeImages(args, "reference", ref.mean, ref.meanIndirect))) return 1;
    std::vector<Result> results;
    std::optional<Parts> parts;
    if (!measureAll(app, args, settings, ref, parts, results)) return 1;
    if (args.time > 0) {  // at t = 0 nothing has moved yet
        Result moving;
        if (!measureMoving(app, args, ref, parts, moving)) return 1;
        results.push_back(std::move(moving));
    }
    const ReferenceFigures figures = referenceFigures(ref, args, results.front().counted);

    fs::create_directories(args.outDir);
    const std::string csvPath = (fs::path(args.outDir) / "quality.csv").string();
    writeErrors(results, figures.ssimMeaningful, csvPath);
    printBias(results);
    const std::string pngPath = (fs::path(args.outDir) / "quality.png").string();
    if (!plotQuality(args, context->description(), csvPath, pngPath, error)) return fail(error) ? 0 : 1;

    const std::string summaryPath = (fs::path(args.outDir) / "summary.json").string();
    std::ofstream(summaryPath) << summary(args, context->description(), app.scene().time(), results, figures, ref,
                                          started).dump(2) << '\n';
    std::printf("wrote %s, %s and %s\n", csvPath.c_str(), pngPath.c_str(), summaryPath.c_str());
    return 0;
}
