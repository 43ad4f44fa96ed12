// kiln-bench-quality at 32×32 (a tiny sweep): one CSV row per setting, every value
// finite, a Pareto front, and the reference served from its cache the second time.
// kiln-bench-render --grow at 32×32: one growth row per count. Bad arguments are named
// usage errors before anything renders.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <sstream>
#include <vector>

#include "kiln/image_io.hpp"
#include "support/run_kiln.hpp"

using namespace kiln::test;

namespace {

// One CSV line's cells (quoted cells may hold commas; the quotes are dropped).
std::vector<std::string> csvCells(const std::string& line) {
    std::vector<std::string> cells(1);
    bool quoted = false;
    for (char c : line) {
        if (c == '"') quoted = !quoted;
        else if (c == ',' && !quoted) cells.emplace_back();
        else cells.back() += c;
    }
    return cells;
}

// quality.csv as rows of named cells.
struct QualityCsv {
    std::vector<std::string> header;
    std::vector<std::vector<std::string>> rows;
    explicit QualityCsv(const std::string& text) {
        std::istringstream in(text);
        std::string line;
        if (std::getline(in, line)) header = csvCells(line);
        while (std::getline(in, line)) rows.push_back(csvCells(line));
    }
    int column(const std::string& name) const {
        for (size_t i = 0; i < header.size(); ++i)
            if (header[i] == name) return int(i);
        FAIL("quality.csv has no column " << name);
        return -1;
    }
    // The cell as a number; NaN when empty (SSIM withheld).
    double number(size_t row, const std::string& name) const {
        const std::string& cell = rows.at(row).at(size_t(column(name)));
        return cell.empty() ? std::nan("") : std::stod(cell);
    }
    const std::string& text(size_t row, const std::string& name) const { return rows.at(row).at(size_t(column(name))); }
};

}  // namespace

TEST_CASE("kiln-bench-quality: a tiny sweep writes one finite CSV row per setting and caches the reference",
          "[integration][bench]") {
    const std::string out = std::string(TEST_OUTPUT_DIR) + "/bench-quality";
    std::filesystem::remove_all(out);
    const std::string args = "--size 32x32 --spp 8 --frames 1 --repeats 2 --time 0.1 --sweep composite.pcf=1,9 "
                             "--also pipelines/course.json --out " + out;
    Run first = runProgram(KILN_BENCH_QUALITY, args, 300);
    INFO(first.out << first.err);
    REQUIRE(first.exitCode == 0);
    const QualityCsv csv(slurp(out + "/quality.csv"));
    int rows = 0, front = 0, courseRows = 0, movingRow = -1;
    for (size_t i = 0; i < csv.rows.size(); ++i) {
        ++rows;
        courseRows += csv.text(i, "setting") == "course";
        if (csv.text(i, "setting") == "default (moving)") movingRow = int(i);
        for (const char* name : {"total_gpu_ms", "rmse", "rel_mse", "psnr", "pixels", "rel_mse_indirect", "rel_mse_floor",
                                 "rel_mse_walls", "rel_mse_ceiling", "rel_mse_objects", "rel_mse_corrected",
                                 "rel_mse_indirect_corrected", "mean_ratio_all", "mean_ratio_all_uncertainty",
                                 "mean_ratio_floor", "mean_ratio_ceiling", "indirect_ratio_all"}) {
            INFO(name);
            CHECK(std::isfinite(csv.number(i, name)));
        }
        CHECK(csv.number(i, "total_gpu_ms") > 0.0);  // the passes cost something
        CHECK(csv.number(i, "rmse") > 0.0);          // 8 paths/px: the reference is noisy, never equal
        // 8 paths/px: the reference's halves disagree far below SSIM 0.97, so SSIM is withheld.
        CHECK(csv.text(i, "ssim").empty());
        CHECK(csv.number(i, "pixels") > 32 * 32 / 2);  // most pixels counted (emitters masked)
        front += csv.number(i, "pareto") == 1.0;
        // Every part of the box is in view and has an error of its own (the emitter-free
        // ceiling around the lamp included), and so has the indirect part.
        for (const char* name : {"rel_mse_indirect", "rel_mse_floor", "rel_mse_walls", "rel_mse_ceiling", "rel_mse_objects"})
            CHECK(csv.number(i, name) > 0.0);
        // The correction removes the reference's own noise: less than the raw figure.
        CHECK(csv.number(i, "rel_mse_corrected") < csv.number(i, "rel_mse"));
        CHECK(csv.number(i, "mean_ratio_all") > 0.0);
        CHECK(csv.number(i, "mean_ratio_all_uncertainty") > 0.0);
        CHECK(csv.text(i, "pass_ms").find("cone_trace=") != std::string::npos);
    }
    const std::string summary = slurp(out + "/summary.json");
    CHECK(summary.find("\"ref_noise_rel_mse\"") != std::string::npos);
    CHECK(rows == 5);  // default, course (--also), 2 sweep values, the default while the scene moves
    CHECK(courseRows == 1);
    // The moving row is the default pipeline rendered as the scene steps to t = 0.1: the
    // frozen frame but for what lags behind motion (the voxels' fed-back bounces), so its
    // error is within 20 % of the frozen default's (at 32² and 8 paths most of either is
    // the reference's noise, which they share); a moving run that reached another moment
    // is refused by the bench, and one that rendered something else is far off.
    REQUIRE(movingRow > 0);
    CHECK(csv.number(size_t(movingRow), "rel_mse") == Approx(csv.number(0, "rel_mse")).epsilon(0.2));
    CHECK(front >= 1);
    Run second = runProgram(KILN_BENCH_QUALITY, args, 300);
    CHECK(second.exitCode == 0);
    CHECK(second.out.find("(cached)") != std::string::npos);
    // Another output folder shares the cache through --cache; another moment of the
    // simulation is another reference.
    const std::string shared = "--size 32x32 --spp 8 --frames 1 --repeats 1 --sweep composite.pcf=1 --cache " + out +
                               "/cache --out " + out + "-b";
    Run third = runProgram(KILN_BENCH_QUALITY, shared + " --time 0.1", 300);
    CHECK(third.exitCode == 0);
    CHECK(third.out.find("(cached)") != std::string::npos);
    Run later = runProgram(KILN_BENCH_QUALITY, shared + " --time 0.2", 300);
    CHECK(later.exitCode == 0);
    CHECK(later.out.find("(cached)") == std::string::npos);
    CHECK(later.out.find("cached as " + out + "/cache/") != std::string::npos);
}

TEST_CASE("kiln-bench-quality on a glTF scene: figures per material and per --region box, and the reference's rays/s",
          "[integration][bench]") {
    // The two rooms: no box, so the regions are the materials each pixel's centre ray
    // meets; a --region over the whole scene holds exactly the counted pixels, so its
    // figures are the "all" figures to the last digit.
    const std::string out = std::string(TEST_OUTPUT_DIR) + "/bench-quality-gltf";
    std::filesystem::remove_all(out);
    Run r = runProgram(KILN_BENCH_QUALITY,
                       "--scene scenes/two_rooms.gltf --time 0 --size 32x32 --spp 8 --frames 1 --repeats 1 "
                       "--sweep composite.pcf=1 --region dark_room=0.09,-0.01,-2.01,4.11,3.01,2.01 "
                       "--region everything=-100,-100,-100,100,100,100 --out " + out,
                       300);
    INFO(r.out << r.err);
    REQUIRE(r.exitCode == 0);
    const QualityCsv csv(slurp(out + "/quality.csv"));
    REQUIRE(csv.rows.size() == 2);
    for (size_t i = 0; i < csv.rows.size(); ++i) {
        for (const char* name : {"rel_mse_partition", "rel_mse_plaster", "rel_mse_floor", "rel_mse_dark_room",
                                 "mean_ratio_partition", "mean_ratio_dark_room", "indirect_ratio_dark_room"}) {
            INFO(name);
            CHECK(std::isfinite(csv.number(i, name)));
            CHECK(csv.number(i, name) > 0.0);
        }
        CHECK(csv.number(i, "mean_ratio_everything") == csv.number(i, "mean_ratio_all"));
        CHECK(csv.number(i, "rel_mse_everything") == Approx(csv.number(i, "rel_mse")).epsilon(1e-9));
    }
    CHECK(csv.header.end() == std::find(csv.header.begin(), csv.header.end(), "rel_mse_ceiling"));  // no box words
    const std::string summary = slurp(out + "/summary.json");
    const size_t at = summary.find("\"reference_rays_per_s\": ");
    REQUIRE(at != std::string::npos);
    CHECK(std::stod(summary.substr(at + 24)) > 0.0);
    CHECK(r.out.find("M rays/s") != std::string::npos);

    Run bad = runProgram(KILN_BENCH_QUALITY, "--region dark=1,2,3", 60);
    CHECK(bad.exitCode == 2);
    CHECK(bad.err.find("--region dark: expected six numbers") != std::string::npos);
}

TEST_CASE("kiln-bench-quality: a pipeline or scene file it cannot read is a usage error before the reference renders",
          "[integration][bench]") {
    for (const char* option : {"--also", "--pipeline", "--scene"}) {
        Run r = runProgram(KILN_BENCH_QUALITY, std::string(option) + " no/such/file.json", 60);
        INFO(r.out << r.err);
        CHECK(r.exitCode == 2);
        CHECK(r.err.find(std::string(option) + ": no/such/file.json: cannot read the file") != std::string::npos);
        CHECK(r.out.find("reference") == std::string::npos);
    }
}

TEST_CASE("kiln-bench-render --grow: one growth row per count, the first the baseline, bad arguments and failing passes are errors",
          "[integration][bench]") {
    const std::string out = std::string(TEST_OUTPUT_DIR) + "/bench-grow";
    std::filesystem::remove_all(out);
    Run r = runProgram(KILN_BENCH_RENDER,
                       "--size 32x32 --frames 1 --repeats 1 --settle 0.3 --grow fireballs=0,4 --out " + out, 300);
    INFO(r.out << r.err);
    REQUIRE(r.exitCode == 0);
    std::istringstream csv(slurp(out + "/growth.csv"));
    std::string line;
    std::getline(csv, line);
    CHECK(line == "pipeline,fireballs,particles,frame_ms,ratio,voxelize_ms,gbuffer_ms,shadow_ms,"
                  "paired_ratio,paired_min,paired_max");
    std::vector<std::vector<double>> rows;
    while (std::getline(csv, line)) {
        std::istringstream cells(line.substr(line.find(',') + 1));
        std::vector<double> v(10);
        char comma;
        for (double& x : v) cells >> x >> comma;
        rows.push_back(v);
    }
    REQUIRE(rows.size() == 2);
    CHECK(rows[0][0] == 0);
    CHECK(rows[1][0] == 4);
    CHECK(rows[0][1] == 0);   // no fireball, no fire
    CHECK(rows[1][1] > 0);    // 0.3 s of four fireballs: particles
    CHECK(rows[0][3] == 1.0); // the baseline's ratio
    CHECK(rows[0][7] == 1.0); // and paired with itself, round by round
    // One round: its ratio is the ratio of the medians, its lowest and highest too.
    CHECK(rows[1][7] == Approx(rows[1][3]).epsilon(1e-5));
    CHECK(rows[1][8] == Approx(rows[1][7]).epsilon(1e-5));
    CHECK(rows[1][9] == Approx(rows[1][7]).epsilon(1e-5));
    for (auto& v : rows)
        for (double x : v) CHECK(std::isfinite(x));
    CHECK(std::filesystem::file_size(out + "/growth.png") > 1000);
    // The grown scene files are what the simulation loaded: four fireballs in the second.
    CHECK(slurp(out + "/scene-fireballs-4.json").find("\"fireballs\"") != std::string::npos);
    // The floor (an empty full-screen pass) is measured and every pass reported as a
    // multiple of it: in render.csv, x_floor = gpu_ms / floor for every row.
    const size_t at = r.out.find("floor: an empty full-screen pass at 32x32");
    REQUIRE(at != std::string::npos);
    const double floorMs = std::stod(r.out.substr(r.out.find(" takes ", at) + 7));
    CHECK(floorMs > 0.0);
    std::istringstream render(slurp(out + "/render.csv"));
    std::getline(render, line);
    CHECK(line == "config,pass,module,gpu_ms,cpu_ms,frame_ms,x_floor");
    int passRows = 0;
    while (std::getline(render, line)) {
        const std::vector<std::string> cells = csvCells(line);
        REQUIRE(cells.size() == 7);
        // The printed floor has three decimals; the CSV's multiple is of the unrounded
        // one, which lies within 0.0005 ms of it (at 32² the floor is about 0.01 ms: a
        // relative tolerance, as this was, went over 100 % there and Catch refused it).
        // 1 % more for the CSV's own rounding.
        const double gpu = std::stod(cells[3]), multiple = std::stod(cells[6]);
        CHECK(multiple >= 0.99 * gpu / (floorMs + 0.0005));
        if (floorMs > 0.0005) CHECK(multiple <= 1.01 * gpu / (floorMs - 0.0005));
        ++passRows;
    }
    CHECK(passRows >= 2 * 5);  // two configurations, every pass of the default

    for (const char* bad : {"--grow comets=1", "--grow fireballs=x", "--grow fireballs=-1", "--settle 99",
                            "--sweep shadow.size=256,512 --grow fireballs=1"}) {
        Run b = runProgram(KILN_BENCH_RENDER, std::string(bad) + " --out " + out, 60);
        INFO(bad << ": " << b.err);
        CHECK(b.exitCode == 2);
        CHECK(b.err.find("kiln-bench-render: error: " + std::string(bad).substr(0, std::string(bad).find(' '))) !=
              std::string::npos);
    }
    Run missing = runProgram(KILN_BENCH_RENDER, "--scene no/such.json --grow fireballs=1 --out " + out, 60);
    CHECK(missing.exitCode == 2);
    CHECK(missing.err.find("no/such.json: cannot read the scene file") != std::string::npos);
    // A configuration whose pass fails did not do its work: an error, not a time.
    Run failing = runProgram(KILN_BENCH_RENDER,
                             "--size 32x32 --frames 1 --repeats 1 --settle 0.1 --set cone_trace.cones=9 --out " + out, 120);
    INFO(failing.out << failing.err);
    CHECK(failing.exitCode == 1);
    CHECK(failing.err.find("cones 9: the fixed set traces 6 cones a pixel") != std::string::npos);
    CHECK(failing.out.find("frame (wall, glFinish)") == std::string::npos);
}

TEST_CASE("the default pipeline is closer to the path-traced reference than the course report's design (course.json)",
          "[integration][bench][quality]") {
    // The claim behind the default's settings, checked against the independent path
    // tracer rather than against a finer run of the rasterizer: 128² at t = 0.5 s, a
    // 128-path reference in two seeded halves (~2.5 min here; deterministic figures).
    // 128², the benchmark's size, not less: the default traces one pixel in 4×4 of a
    // half-size image, and at 96² those 12×12 samples smear the lamp's light on the
    // ceiling (the mean light falls to 0.94×). 128 paths, not more: the render dominates
    // the suite's time, and the figures asserted are noise-corrected or means.
    // Measured (noise-corrected relMSE): 0.0206 against 0.0553, the indirect part 0.0310
    // against 0.128; the mean luminance 1.032× the reference's against 0.790× (issue
    // 22: the course design's one bounce misses a fifth of the light; the default has
    // every bounce, fed back across frames, and the first ones' over-reflection shows:
    // 0.967× with three in-frame bounces, which left out the fourth and later). Bounds
    // 0.95–1.05: a missing bounce (0.89× with two) or a doubled one fails. SSIM is
    // withheld at this path count (the halves disagree).
    const std::string out = std::string(TEST_OUTPUT_DIR) + "/bench-quality-default-vs-course";
    Run r = runProgram(KILN_BENCH_QUALITY,
                       "--size 128x128 --spp 128 --frames 1 --repeats 1 --sweep composite.exposure=1 "
                       "--also pipelines/course.json --images --out " + out,
                       600);
    INFO(r.out << r.err);
    REQUIRE(r.exitCode == 0);
    const QualityCsv csv(slurp(out + "/quality.csv"));
    double relMse[2] = {-1, -1}, indirect[2] = {-1, -1}, light[2] = {-1, -1};
    for (size_t i = 0; i < csv.rows.size(); ++i) {
        const std::string& label = csv.text(i, "setting");
        const int which = label == "default" ? 0 : label == "course" ? 1 : -1;
        if (which < 0) continue;
        relMse[which] = csv.number(i, "rel_mse_corrected");
        indirect[which] = csv.number(i, "rel_mse_indirect_corrected");
        light[which] = csv.number(i, "mean_ratio_all");
    }
    INFO("relMSE default " << relMse[0] << " course " << relMse[1] << "; indirect " << indirect[0] << " / " << indirect[1]);
    REQUIRE(relMse[0] > 0);
    REQUIRE(relMse[1] > 0);
    CHECK(relMse[0] < relMse[1]);
    CHECK(indirect[0] < indirect[1]);
    INFO("mean luminance ÷ the reference's: default " << light[0] << ", course " << light[1]);
    CHECK(light[0] > 0.95);
    CHECK(light[0] < 1.05);
    CHECK(light[1] < 0.9);

    // --images: each setting's frame and indirect part and the reference's, at the size;
    // the indirect part holds light, less than the frame it was taken from.
    for (const char* name : {"reference", "default", "course", "composite.exposure=1"}) {
        INFO(name);
        kiln::FloatImage frame, indirect;
        std::string error;
        REQUIRE(kiln::readExr(out + "/images/" + name + ".exr", frame, error));
        REQUIRE(kiln::readExr(out + "/images/" + name + ".indirect.exr", indirect, error));
        CHECK(frame.width == 128);
        CHECK(indirect.height == 128);
        double sumFrame = 0, sumIndirect = 0;
        for (size_t i = 0; i < frame.pixels.size(); ++i) sumFrame += frame.pixels[i], sumIndirect += indirect.pixels[i];
        CHECK(sumIndirect > 0.0);
        CHECK(sumIndirect < sumFrame);
    }
}
