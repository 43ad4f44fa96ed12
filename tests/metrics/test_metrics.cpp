// Error metrics on pairs whose answers are known in closed form, and RMSE/PSNR
// cross-checked against OpenImageIO's idiff (an independent implementation).
#include <catch2/catch.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <random>
#include <string>

#include "kiln/image_io.hpp"
#include "metrics.hpp"

using namespace kiln;
namespace m = kiln::metrics;

namespace {

FloatImage constant(int w, int h, std::array<float, 3> rgb) {
    FloatImage img;
    img.width = w, img.height = h, img.channels = 4;
    img.pixels.resize(size_t(w) * h * 4);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            float* p = img.at(x, y);
            p[0] = rgb[0], p[1] = rgb[1], p[2] = rgb[2], p[3] = 1.0f;
        }
    return img;
}

FloatImage noise(int w, int h, unsigned seed, float lo = 0.0f, float hi = 1.0f) {
    FloatImage img = constant(w, h, {0, 0, 0});
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(lo, hi);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            for (int c = 0; c < 3; ++c) img.at(x, y)[c] = u(rng);
    return img;
}

}  // namespace

TEST_CASE("metrics: RMSE and PSNR of a constant offset are the offset and 20·log10(1/offset)", "[metrics]") {
    const FloatImage r = noise(16, 12, 1), i = [&] {
        FloatImage x = r;
        for (size_t k = 0; k < x.pixels.size(); ++k)
            if (k % 4 != 3) x.pixels[k] += 0.1f;
        return x;
    }();
    CHECK(m::rmse(i, r) == Approx(0.1).epsilon(1e-6));  // float storage: ~1e-7 relative
    CHECK(m::psnr(m::rmse(i, r)) == Approx(20.0).epsilon(1e-5));
    CHECK(m::rmse(r, r) == 0.0);
}

TEST_CASE("metrics: relative MSE of twice the reference is mean R²/(R²+ε)", "[metrics]") {
    // (2R − R)² / (R² + ε) = R² / (R² + ε); for R = 0.1 and ε = 0.01: 0.5; for R = 1: 1/1.01.
    FloatImage r = constant(8, 8, {0.1f, 0.1f, 0.1f});
    for (int y = 0; y < 4; ++y)
        for (int x = 0; x < 8; ++x) r.at(x, y)[0] = r.at(x, y)[1] = r.at(x, y)[2] = 1.0f;
    FloatImage i = r;
    for (size_t k = 0; k < i.pixels.size(); ++k) i.pixels[k] *= 2.0f;
    CHECK(m::relativeMse(i, r) == Approx(0.5 * (0.01 / 0.02) + 0.5 * (1.0 / 1.01)).epsilon(1e-6));
}

TEST_CASE("metrics: a mask leaves pixels out", "[metrics]") {
    FloatImage r = constant(4, 4, {0.5f, 0.5f, 0.5f}), i = r;
    i.at(3, 3)[0] = 100.0f;  // an "emitter"
    m::Mask mask(16, 1);
    mask[3 * 4 + 3] = 0;
    CHECK(m::rmse(i, r) > 1.0);
    CHECK(m::rmse(i, r, mask) == 0.0);
    CHECK(m::compare(i, r, mask).pixels == 15);
}

TEST_CASE("metrics: SSIM is 1 for identical images, the closed form for constants, lower for noise", "[metrics]") {
    const int w = 24, h = 24;
    const FloatImage a = noise(w, h, 2);
    const auto la = m::displayLuminance(a);
    CHECK(m::ssim(la, la, w, h) == Approx(1.0).epsilon(1e-12));
    // Two constant images a, b: no variance, so SSIM = (2ab + C1)/(a² + b² + C1).
    std::vector<double> ca(size_t(w) * h, 0.3), cb(size_t(w) * h, 0.6);
    const double c1 = 0.01 * 0.01;
    CHECK(m::ssim(ca, cb, w, h) == Approx((2 * 0.3 * 0.6 + c1) / (0.09 + 0.36 + c1)).epsilon(1e-12));
    // Independent noise of the same statistics: structure uncorrelated, SSIM near 0.
    const auto lb = m::displayLuminance(noise(w, h, 3));
    const double s = m::ssim(la, lb, w, h);
    CHECK(std::abs(s) < 0.2);
    CHECK(m::ssim(lb, la, w, h) == Approx(s).epsilon(1e-12));  // symmetric
}

TEST_CASE("metrics: RMSE and PSNR agree with OpenImageIO's idiff on EXR files Kiln wrote", "[metrics][exr]") {
    // idiff reads both files (so this also checks the EXR writer: orientation, channel
    // count) and prints "RMS error = X" and "Peak SNR = Y" over all channels; both
    // images are written RGB, so the channels are the ones Kiln's RMSE averages.
    std::filesystem::create_directories(TEST_OUTPUT_DIR);
    const std::string fa = std::string(TEST_OUTPUT_DIR) + "/a.exr", fb = std::string(TEST_OUTPUT_DIR) + "/b.exr";
    FloatImage a = noise(37, 23, 4), b = noise(37, 23, 5, 0.0f, 1.5f);
    a.channels = b.channels = 4;
    FloatImage a3 = a, b3 = b;
    for (FloatImage* img : {&a3, &b3}) {  // RGB only on disk
        std::vector<float> rgb;
        for (size_t k = 0; k < img->pixels.size(); ++k)
            if (k % 4 != 3) rgb.push_back(img->pixels[k]);
        img->pixels = rgb, img->channels = 3;
    }
    std::string error;
    REQUIRE(writeExr(fa, a3, error));
    REQUIRE(writeExr(fb, b3, error));
    FloatImage back;
    REQUIRE(readExr(fa, back, error));
    REQUIRE(back.width == a.width);
    CHECK(back.at(5, 7)[1] == a.at(5, 7)[1]);  // bottom-up on both sides, 32-bit float

    std::unique_ptr<FILE, int (*)(FILE*)> pipe(popen(("idiff -a '" + fa + "' '" + fb + "' 2>&1").c_str(), "r"), pclose);
    REQUIRE(pipe);
    std::string out;
    char buffer[512];
    while (fgets(buffer, sizeof buffer, pipe.get())) out += buffer;
    INFO(out);
    double idiffRms = -1, idiffPsnr = -1;
    if (auto at = out.find("RMS error = "); at != std::string::npos) idiffRms = std::stod(out.substr(at + 12));
    if (auto at = out.find("Peak SNR = "); at != std::string::npos) idiffPsnr = std::stod(out.substr(at + 11));
    REQUIRE(idiffRms > 0);
    const double ours = m::rmse(a, b);
    // idiff prints 6 significant digits.
    CHECK(ours == Approx(idiffRms).epsilon(2e-6));
    // idiff's PSNR takes the largest value in the images as the peak.
    float peak = 0.0f;
    for (size_t k = 0; k < a.pixels.size(); ++k)
        if (k % 4 != 3) peak = std::max({peak, a.pixels[k], b.pixels[k]});
    INFO("peak " << peak);
    CHECK(m::psnr(ours, peak) == Approx(idiffPsnr).epsilon(2e-6));
}
