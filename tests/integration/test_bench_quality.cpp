// kiln-bench-quality at 32×32 (a tiny sweep): one CSV row per setting, every value
// finite, a Pareto front, and the reference served from its cache the second time.
#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <sstream>

#include "support/run_kiln.hpp"

using namespace kiln::test;

TEST_CASE("kiln-bench-quality: a tiny sweep writes one finite CSV row per setting and caches the reference",
          "[integration][bench]") {
    const std::string out = std::string(TEST_OUTPUT_DIR) + "/bench-quality";
    std::filesystem::remove_all(out);
    const std::string args = "--size 32x32 --spp 8 --frames 1 --repeats 2 --time 0.1 --sweep cone_trace.cones=1,9 --out " + out;
    Run first = runProgram(KILN_BENCH_QUALITY, args, 300);
    INFO(first.out << first.err);
    REQUIRE(first.exitCode == 0);
    std::istringstream csv(slurp(out + "/quality.csv"));
    std::string line;
    std::getline(csv, line);
    CHECK(line == "setting,total_gpu_ms,rmse,rel_mse,ssim,psnr,pixels,pareto,rel_mse_indirect,rel_mse_floor,rel_mse_walls,"
                  "rel_mse_ceiling,rel_mse_objects,pass_ms");
    int rows = 0, front = 0;
    while (std::getline(csv, line)) {
        ++rows;
        // "label",ms,rmse,relmse,ssim,psnr,pixels,pareto,indirect,floor,walls,ceiling,objects,"passes"
        std::istringstream cells(line.substr(line.find("\",") + 2));
        double v[12];
        char comma;
        for (double& x : v) cells >> x >> comma;
        for (double x : v) CHECK(std::isfinite(x));
        CHECK(v[0] > 0.0);                  // the passes cost something
        CHECK(v[1] > 0.0);                  // 8 paths/px: the reference is noisy, never equal
        CHECK((v[3] > -1.0 && v[3] <= 1.0));  // SSIM
        CHECK(v[5] > 32 * 32 / 2);          // most pixels counted (emitters masked)
        front += v[6] == 1.0;
        // Every part of the box is in view and has an error of its own (the emitter-free
        // ceiling around the lamp included), and so has the indirect part.
        for (int k = 7; k < 12; ++k) CHECK(v[k] > 0.0);
        CHECK(line.find("cone_trace=") != std::string::npos);
    }
    CHECK(rows == 3);  // default + 2 sweep values
    CHECK(front >= 1);
    Run second = runProgram(KILN_BENCH_QUALITY, args, 300);
    CHECK(second.exitCode == 0);
    CHECK(second.out.find("(cached)") != std::string::npos);
}
