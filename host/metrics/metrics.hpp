// metrics/metrics.hpp — how far an image is from a reference (SPEC §7).
//
// Radiance metrics work on linear HDR RGB (before bloom and tonemapping):
//   RMSE           √ mean over pixels and channels of (I − R)²
//   relative MSE   mean of (I − R)² / (R² + ε), ε = 0.01: errors in dark regions count
//                  as much as in bright ones (Rousselle et al.), ε keeps black finite
//   PSNR           20·log10(peak / RMSE)
// SSIM (Wang et al. 2004: 11×11 Gaussian window, σ = 1.5, K1 = 0.01, K2 = 0.03, L = 1)
// works on display luminance: the radiance tonemapped with the ACES fit and gamma 2.2
// (common/tonemap.glsl), then Rec. 709 luminance — what the eye compares.
// A mask (one byte per pixel, non-zero = counted) leaves pixels out, e.g. emitters,
// whose radiance is copied, not computed.
#pragma once

#include <cstdint>
#include <vector>

#include "kiln/float_image.hpp"

namespace kiln::metrics {

using Mask = std::vector<uint8_t>;  // width × height, row 0 = bottom; empty = all pixels

struct Errors {
    double rmse = 0, relMse = 0, psnr = 0, ssim = 0;
    int pixels = 0;  // counted
};

inline constexpr double kRelMseEpsilon = 0.01;

double rmse(const FloatImage& image, const FloatImage& reference, const Mask& mask = {});
double relativeMse(const FloatImage& image, const FloatImage& reference, const Mask& mask = {},
                   double epsilon = kRelMseEpsilon);
double psnr(double rmse, double peak = 1.0);
// Luminance of the displayed image (ACES, gamma 2.2), one value per pixel.
std::vector<double> displayLuminance(const FloatImage& radiance, double exposure = 1.0);
// Mean SSIM over the pixels the mask keeps (windows clipped at the borders).
double ssim(const std::vector<double>& a, const std::vector<double>& b, int width, int height, const Mask& mask = {});
// All four at once; SSIM on displayLuminance of both.
Errors compare(const FloatImage& image, const FloatImage& reference, const Mask& mask = {});
// `a − b` per pixel and channel (e.g. total − direct = the indirect part).
FloatImage difference(const FloatImage& a, const FloatImage& b);

}  // namespace kiln::metrics
