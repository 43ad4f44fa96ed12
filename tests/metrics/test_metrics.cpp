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

// A reference made of two independent halves A and B (see metrics.hpp). The halves
// here are a known truth T plus independent Gaussian noise, so every expected value is
// a closed form in T, σ and ε; tolerances allow for the sampling noise of 128² pixels
// and for the bias of the noisy denominator R² + ε (a few per cent at these settings).
namespace {

// `truth` plus independent N(0, sigma²) noise on each pixel's RGB.
FloatImage withGaussianNoise(const FloatImage& truth, float sigma, unsigned seed) {
    FloatImage img = truth;
    std::mt19937 rng(seed);
    std::normal_distribution<float> n(0.0f, sigma);
    for (int y = 0; y < img.height; ++y)
        for (int x = 0; x < img.width; ++x)
            for (int c = 0; c < 3; ++c) img.at(x, y)[c] += n(rng);
    return img;
}

}  // namespace

TEST_CASE("metrics: against a noisy reference, the truth itself has a noise-corrected relMSE near 0", "[metrics]") {
    const int w = 128, h = 128;
    const double truth = 0.5, sigma = 0.05, eps = m::kRelMseEpsilon;
    const FloatImage t = constant(w, h, {float(truth), float(truth), float(truth)});
    const FloatImage a = withGaussianNoise(t, float(sigma), 11), b = withGaussianNoise(t, float(sigma), 12);
    // R = (A + B)/2 has variance σ²/2 per channel, so its relMSE against the truth is
    // about (σ²/2)/(T² + ε) = 0.00125/0.26 = 0.00481.
    const double noiseRelMse = (sigma * sigma / 2) / (truth * truth + eps);
    const double raw = m::relativeMse(t, m::average(a, b));
    INFO("raw " << raw << ", expected noise " << noiseRelMse);
    CHECK(raw == Approx(noiseRelMse).epsilon(0.10));  // the raw figure is all reference noise
    CHECK(m::referenceNoiseRelativeMse(a, b) == Approx(noiseRelMse).epsilon(0.10));
    // Corrected: within 10 % of the noise it removed (measured: ~3 %, the denominator's
    // bias at T = 0.5 with σ(R)/T = 7 %).
    const double corrected = m::noiseCorrectedRelativeMse(t, a, b);
    INFO("corrected " << corrected);
    CHECK(std::abs(corrected) < 0.10 * noiseRelMse);
    // Same denominators: the corrected figure is the raw one less the noise floor.
    CHECK(raw - m::referenceNoiseRelativeMse(a, b) == Approx(corrected).margin(1e-12));
}

TEST_CASE("metrics: the noise-corrected relMSE of a biased image is its relMSE against the truth", "[metrics]") {
    const int w = 128, h = 128;
    const double truth = 0.5, sigma = 0.03, offset = 0.05, eps = m::kRelMseEpsilon;
    const FloatImage t = constant(w, h, {float(truth), float(truth), float(truth)});
    // ± offset on alternate pixels: the same error everywhere, and the noisy denominator's
    // first-order bias (∝ K − T, metrics.hpp) cancels between the two signs.
    FloatImage k = t;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            for (int c = 0; c < 3; ++c) k.at(x, y)[c] += float((x + y) % 2 ? offset : -offset);
    const FloatImage a = withGaussianNoise(t, float(sigma), 21), b = withGaussianNoise(t, float(sigma), 22);
    const double trueRelMse = offset * offset / (truth * truth + eps);            // 0.0025/0.26 = 0.00962
    const double noiseRelMse = (sigma * sigma / 2) / (truth * truth + eps);       // 0.00045/0.26 = 0.00173
    const double raw = m::relativeMse(k, m::average(a, b)), corrected = m::noiseCorrectedRelativeMse(k, a, b);
    INFO("raw " << raw << ", corrected " << corrected << ", true " << trueRelMse);
    // The raw figure is ~18 % too high; the corrected one within 4 % (measured ~1 %).
    CHECK(raw == Approx(trueRelMse + noiseRelMse).epsilon(0.04));
    CHECK(corrected == Approx(trueRelMse).epsilon(0.04));
    // A mask leaves out pixels whatever their values.
    FloatImage kOff = k;
    kOff.at(0, 0)[0] = 1000.0f;
    m::Mask mask(size_t(w) * h, 1);
    mask[0] = 0;
    CHECK(m::noiseCorrectedRelativeMse(kOff, a, b, mask) == Approx(trueRelMse).epsilon(0.04));
}

TEST_CASE("metrics: mean luminance is Rec. 709 on linear RGB, and a 10 % brighter image has a ratio of 1.10", "[metrics]") {
    const FloatImage c = constant(4, 4, {0.2f, 0.4f, 0.6f});
    CHECK(m::meanLuminance(c) == Approx(0.2126 * 0.2 + 0.7152 * 0.4 + 0.0722 * 0.6).epsilon(1e-6));

    const int w = 64, h = 64;
    const FloatImage t = noise(w, h, 31, 0.2f, 1.0f);
    FloatImage k = t;
    for (size_t i = 0; i < k.pixels.size(); ++i)
        if (i % 4 != 3) k.pixels[i] *= 1.1f;
    CHECK(m::meanLuminanceRatio(k, t) == Approx(1.1).epsilon(1e-6));  // exact truth: float rounding only
    // Against a noisy reference (σ = 0.05 a channel a half): the ratio within 0.005 of
    // 1.10 (its own σ is ~0.0008 here), and the stated uncertainty close to the closed
    // form 1.1 · σ(mean L(R)) / mean L(T), σ(mean L(R)) = √(Σ w²) · σ/√2 / √n.
    const double sigma = 0.05;
    const FloatImage a = withGaussianNoise(t, float(sigma), 32), b = withGaussianNoise(t, float(sigma), 33);
    const m::RatioWithUncertainty r = m::meanLuminanceRatio(k, a, b);
    const double sumW2 = 0.2126 * 0.2126 + 0.7152 * 0.7152 + 0.0722 * 0.0722;
    const double expectedSigma = 1.1 * std::sqrt(sumW2) * sigma / std::sqrt(2.0) / std::sqrt(double(w * h)) / m::meanLuminance(t);
    INFO("ratio " << r.ratio << " ± " << r.uncertainty << ", expected ± " << expectedSigma);
    CHECK(r.ratio == Approx(1.1).margin(0.005));
    CHECK(r.uncertainty == Approx(expectedSigma).epsilon(0.05));
    // Masked out: an "emitter" far brighter in the image than in the reference.
    FloatImage kGlow = k;
    kGlow.at(5, 5)[0] = kGlow.at(5, 5)[1] = kGlow.at(5, 5)[2] = 500.0f;
    m::Mask mask(size_t(w) * h, 1);
    mask[5 * w + 5] = 0;
    CHECK(m::meanLuminanceRatio(kGlow, t) > 1.2);  // 500/4096 more on a mean of ~0.6: ~1.30
    CHECK(m::meanLuminanceRatio(kGlow, t, mask) == Approx(1.1).epsilon(1e-6));
    // Nothing counted, or a black reference: no ratio.
    CHECK(std::isnan(m::meanLuminanceRatio(k, t, m::Mask(size_t(w) * h, 0))));
    CHECK(std::isnan(m::meanLuminanceRatio(k, constant(w, h, {0, 0, 0}))));
}

TEST_CASE("metrics: the luminance ratio's stated uncertainty is its spread over independent references", "[metrics]") {
    // 400 references of 16² pixels, each two fresh halves: the standard deviation of the
    // ratios must match the RMS of the stated uncertainties within 15 % (the spread of
    // 400 draws is itself known to ~4 %). The ± half the difference of the ratios
    // against A and against B alone would average only √(2/π) ≈ 0.8 of it.
    const int w = 16, h = 16, trials = 400;
    const FloatImage t = noise(w, h, 41, 0.2f, 1.0f);
    FloatImage k = t;
    for (size_t i = 0; i < k.pixels.size(); ++i) k.pixels[i] *= 0.9f;
    double sum = 0, sumSquares = 0, sumUncertaintySquares = 0;
    for (int i = 0; i < trials; ++i) {
        const m::RatioWithUncertainty r =
            m::meanLuminanceRatio(k, withGaussianNoise(t, 0.1f, 1000 + 2 * i), withGaussianNoise(t, 0.1f, 1001 + 2 * i));
        sum += r.ratio, sumSquares += r.ratio * r.ratio, sumUncertaintySquares += r.uncertainty * r.uncertainty;
    }
    const double mean = sum / trials, spread = std::sqrt((sumSquares - trials * mean * mean) / (trials - 1));
    const double stated = std::sqrt(sumUncertaintySquares / trials);
    INFO("mean " << mean << ", spread " << spread << ", stated " << stated);
    CHECK(mean == Approx(0.9).margin(0.002));
    CHECK(stated == Approx(spread).epsilon(0.15));
}
