#include "metrics.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace kiln::metrics {

namespace {

void checkShapes(const FloatImage& a, const FloatImage& b, const Mask& mask) {
    if (a.width != b.width || a.height != b.height)
        throw std::invalid_argument("metrics: images differ in size (" + std::to_string(a.width) + "x" +
                                    std::to_string(a.height) + " vs " + std::to_string(b.width) + "x" +
                                    std::to_string(b.height) + ")");
    if (!mask.empty() && mask.size() != size_t(a.width) * size_t(a.height))
        throw std::invalid_argument("metrics: mask size does not match the image");
}

bool counted(const Mask& mask, size_t pixel) { return mask.empty() || mask[pixel] != 0; }

// Mean over counted pixels and the RGB channels of f(k, a, b), one value of each image.
template <class F>
double meanOver3(const FloatImage& k, const FloatImage& a, const FloatImage& b, const Mask& mask, F f) {
    checkShapes(k, a, mask);
    checkShapes(a, b, mask);
    double sum = 0.0;
    size_t n = 0;
    for (int y = 0; y < a.height; ++y)
        for (int x = 0; x < a.width; ++x) {
            if (!counted(mask, size_t(y) * a.width + x)) continue;
            for (int c = 0; c < 3; ++c)
                sum += f(double(k.at(x, y)[c]), double(a.at(x, y)[c]), double(b.at(x, y)[c]));
            n += 3;
        }
    return n ? sum / double(n) : 0.0;
}

// Mean over counted pixels and the RGB channels of f(image value, reference value).
template <class F>
double meanOver(const FloatImage& a, const FloatImage& b, const Mask& mask, F f) {
    return meanOver3(a, b, b, mask, [&f](double image, double reference, double) { return f(image, reference); });
}

double aces(double x) {
    x = std::max(x, 0.0);
    return std::clamp((x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14), 0.0, 1.0);
}

}  // namespace

double rmse(const FloatImage& image, const FloatImage& reference, const Mask& mask) {
    return std::sqrt(meanOver(image, reference, mask, [](double i, double r) { return (i - r) * (i - r); }));
}

double relativeMse(const FloatImage& image, const FloatImage& reference, const Mask& mask, double epsilon) {
    return meanOver(image, reference, mask, [epsilon](double i, double r) { return (i - r) * (i - r) / (r * r + epsilon); });
}

double psnr(double rmse, double peak) { return rmse > 0.0 ? 20.0 * std::log10(peak / rmse) : INFINITY; }

std::vector<double> displayLuminance(const FloatImage& radiance, double exposure) {
    std::vector<double> out(size_t(radiance.width) * radiance.height);
    for (int y = 0; y < radiance.height; ++y)
        for (int x = 0; x < radiance.width; ++x) {
            const float* p = radiance.at(x, y);
            double rgb[3];
            for (int c = 0; c < 3; ++c) rgb[c] = std::pow(aces(p[c] * exposure), 1.0 / 2.2);
            out[size_t(y) * radiance.width + x] = 0.2126 * rgb[0] + 0.7152 * rgb[1] + 0.0722 * rgb[2];
        }
    return out;
}

double ssim(const std::vector<double>& a, const std::vector<double>& b, int width, int height, const Mask& mask) {
    constexpr int kRadius = 5;  // 11 × 11
    constexpr double kSigma = 1.5, kC1 = 0.01 * 0.01, kC2 = 0.03 * 0.03;
    double weights[2 * kRadius + 1];
    for (int i = -kRadius; i <= kRadius; ++i) weights[i + kRadius] = std::exp(-0.5 * i * i / (kSigma * kSigma));
    double sum = 0.0;
    size_t n = 0;
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) {
            if (!counted(mask, size_t(y) * width + x)) continue;
            double w = 0, ma = 0, mb = 0, aa = 0, bb = 0, ab = 0;
            for (int dy = -kRadius; dy <= kRadius; ++dy) {
                const int yy = y + dy;
                if (yy < 0 || yy >= height) continue;
                for (int dx = -kRadius; dx <= kRadius; ++dx) {
                    const int xx = x + dx;
                    if (xx < 0 || xx >= width) continue;
                    const double k = weights[dy + kRadius] * weights[dx + kRadius];
                    const double va = a[size_t(yy) * width + xx], vb = b[size_t(yy) * width + xx];
                    w += k, ma += k * va, mb += k * vb, aa += k * va * va, bb += k * vb * vb, ab += k * va * vb;
                }
            }
            ma /= w, mb /= w;
            const double varA = aa / w - ma * ma, varB = bb / w - mb * mb, cov = ab / w - ma * mb;
            sum += ((2 * ma * mb + kC1) * (2 * cov + kC2)) / ((ma * ma + mb * mb + kC1) * (varA + varB + kC2));
            ++n;
        }
    return n ? sum / double(n) : 1.0;
}

Errors compare(const FloatImage& image, const FloatImage& reference, const Mask& mask) {
    Errors e;
    e.rmse = rmse(image, reference, mask);
    e.relMse = relativeMse(image, reference, mask);
    e.psnr = psnr(e.rmse);
    e.ssim = ssim(displayLuminance(image), displayLuminance(reference), image.width, image.height, mask);
    for (int i = 0; i < image.width * image.height; ++i) e.pixels += counted(mask, size_t(i)) ? 1 : 0;
    return e;
}

FloatImage difference(const FloatImage& a, const FloatImage& b) {
    checkShapes(a, b, {});
    FloatImage d = a;
    for (int y = 0; y < a.height; ++y)
        for (int x = 0; x < a.width; ++x)
            for (int c = 0; c < std::min(3, a.channels); ++c) d.at(x, y)[c] = a.at(x, y)[c] - b.at(x, y)[c];
    return d;
}

FloatImage average(const FloatImage& a, const FloatImage& b) {
    checkShapes(a, b, {});
    if (a.channels != b.channels) throw std::invalid_argument("metrics: images differ in channel count");
    FloatImage mean = a;
    for (size_t i = 0; i < mean.pixels.size(); ++i) mean.pixels[i] = 0.5f * (a.pixels[i] + b.pixels[i]);
    return mean;
}

double referenceNoiseRelativeMse(const FloatImage& halfA, const FloatImage& halfB, const Mask& mask, double epsilon) {
    return meanOver(halfA, halfB, mask, [epsilon](double a, double b) {
        const double r = 0.5 * (a + b);
        return 0.25 * (a - b) * (a - b) / (r * r + epsilon);
    });
}

double noiseCorrectedRelativeMse(const FloatImage& image, const FloatImage& halfA, const FloatImage& halfB,
                                 const Mask& mask, double epsilon) {
    return meanOver3(image, halfA, halfB, mask, [epsilon](double k, double a, double b) {
        const double r = 0.5 * (a + b);
        return ((k - r) * (k - r) - 0.25 * (a - b) * (a - b)) / (r * r + epsilon);
    });
}

double meanLuminance(const FloatImage& radiance, const Mask& mask) {
    checkShapes(radiance, radiance, mask);
    double sum = 0.0;
    size_t n = 0;
    for (int y = 0; y < radiance.height; ++y)
        for (int x = 0; x < radiance.width; ++x)
            if (counted(mask, size_t(y) * radiance.width + x)) sum += luminance(radiance.at(x, y)), ++n;
    return n ? sum / double(n) : 0.0;
}

double meanLuminanceRatio(const FloatImage& image, const FloatImage& reference, const Mask& mask) {
    checkShapes(image, reference, mask);
    const double denominator = meanLuminance(reference, mask);
    return denominator > 0.0 ? meanLuminance(image, mask) / denominator : NAN;
}

RatioWithUncertainty meanLuminanceRatio(const FloatImage& image, const FloatImage& halfA, const FloatImage& halfB,
                                        const Mask& mask) {
    checkShapes(image, halfA, mask);
    checkShapes(halfA, halfB, mask);
    double sumImage = 0.0, sumReference = 0.0, sumVariance = 0.0;
    size_t n = 0;
    for (int y = 0; y < image.height; ++y)
        for (int x = 0; x < image.width; ++x) {
            if (!counted(mask, size_t(y) * image.width + x)) continue;
            const double a = luminance(halfA.at(x, y)), b = luminance(halfB.at(x, y));
            sumImage += luminance(image.at(x, y));
            sumReference += 0.5 * (a + b);
            sumVariance += 0.25 * (a - b) * (a - b);  // of this pixel's L(R)
            ++n;
        }
    RatioWithUncertainty out;
    if (n == 0 || !(sumReference > 0.0)) return out;
    const double meanReference = sumReference / double(n);
    const double sigmaMeanReference = std::sqrt(sumVariance) / double(n);
    out.ratio = (sumImage / double(n)) / meanReference;
    out.uncertainty = std::abs(out.ratio) * sigmaMeanReference / meanReference;
    return out;
}

}  // namespace kiln::metrics
