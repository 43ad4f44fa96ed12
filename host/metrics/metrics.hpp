// metrics/metrics.hpp — how far an image is from a reference (README: "The reference and run time against error").
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
//
// A path-traced reference is the truth plus noise, and an error against it counts that
// noise as the image's error. Rendered as two independent halves A and B (same path
// count, different seeds), its mean R = (A + B)/2 has, per pixel and channel, a
// variance that (A − B)²/4 estimates without bias: E[(A − B)²] = Var A + Var B =
// 4 Var R. Given an image K rendered independently of the reference,
// E[(K − R)²] = (K − truth)² + Var R, so subtracting (A − B)²/4 leaves an estimate of
// K's error against the truth:
//   reference noise        mean of ((A − B)²/4) / (R² + ε): the relative MSE R itself
//                          has against the truth, on expectation
//   noise-corrected relMSE mean of ((K − R)² − (A − B)²/4) / (R² + ε): relative MSE
//                          minus the reference's noise (may be slightly negative for an
//                          image closer to the truth than the reference can tell)
// Both divide by R² + ε like relativeMse, so corrected = relativeMse(K, R) − reference
// noise exactly. The numerator, (K − R)² − (A − B)²/4 = (K − A)(K − B), has expectation
// (K − truth)² exactly; the denominator is noisy too and correlated with it, which
// leaves a bias of about 2 (K − T) · Var R · 2T/(T² + ε)² per pixel (T the truth): for
// T² ≫ ε, the pixel's noise floor times 4 (K − T)/T, of either sign (it cancels where
// K is too bright in some pixels and too dark in others) — small next to the noise
// it removes while K's relative errors are small.
// Bias, not noise: the mean Rec. 709 luminance (0.2126, 0.7152, 0.0722 on linear RGB) of
// K over that of R, with its standard uncertainty from the halves.
#pragma once

#include <cmath>
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
// `(a + b)/2` per pixel and channel: the reference from its two halves.
FloatImage average(const FloatImage& a, const FloatImage& b);

// The relative MSE the reference R = (A + B)/2 has against the truth, on expectation:
// mean of ((A − B)²/4) / (R² + ε).
double referenceNoiseRelativeMse(const FloatImage& halfA, const FloatImage& halfB, const Mask& mask = {},
                                 double epsilon = kRelMseEpsilon);
// An estimate of `image`'s relative MSE against the truth: mean of
// ((K − R)² − (A − B)²/4) / (R² + ε), R = (A + B)/2. `image` must not share random
// numbers with the halves (a rasterized frame does not).
double noiseCorrectedRelativeMse(const FloatImage& image, const FloatImage& halfA, const FloatImage& halfB,
                                 const Mask& mask = {}, double epsilon = kRelMseEpsilon);

// Rec. 709 luminance of linear RGB.
inline double luminance(const float* rgb) { return 0.2126 * rgb[0] + 0.7152 * rgb[1] + 0.0722 * rgb[2]; }
// Mean luminance over the counted pixels (0 when none is counted).
double meanLuminance(const FloatImage& radiance, const Mask& mask = {});
// meanLuminance(image) / meanLuminance(reference): 1.1 = 10 % too bright on average.
// NaN when no pixel is counted or the reference's mean is not positive.
double meanLuminanceRatio(const FloatImage& image, const FloatImage& reference, const Mask& mask = {});

struct RatioWithUncertainty {
    double ratio = NAN;        // against R = (A + B)/2
    double uncertainty = NAN;  // one standard deviation from R's noise
};
// meanLuminanceRatio against R = (A + B)/2, with the standard deviation R's noise gives
// it. The reference's pixels are independent (each draws its own random sequence), so
// Var(mean L(R)) = Σ Var L_i(R) / n², and (L_i(A) − L_i(B))²/4 estimates each term:
// n degrees of freedom, where the spread of the two ratios against A and against B
// alone would be an estimate from one. To first order, σ(ratio) = ratio · σ(mean L(R)) /
// mean L(R) (K is a fixed image, not a random one).
RatioWithUncertainty meanLuminanceRatio(const FloatImage& image, const FloatImage& halfA, const FloatImage& halfB,
                                        const Mask& mask = {});

}  // namespace kiln::metrics
