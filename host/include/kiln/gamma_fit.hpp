// kiln/gamma_fit.hpp — x^(1/γ) on [0, 1] without pow: a polynomial in s = x^(1/4),
// c₁s + c₂s² + c₃s³ + c₄s⁴ (shaders/common/tonemap.glsl, KILN_GAMMA_FIT). Two square
// roots and four multiply-adds a channel instead of pow's exp2 and log2, which a CPU
// rasterizer pays dearly for. In s the curve is s^(4/γ), smooth enough
// for four terms: at γ = 2.2 within 5.2e-4 of pow (0.13 of an 8-bit step), at 1 and 2
// exact; above about 2.35 the error passes kGammaFitTolerance and a pass uses pow.
#pragma once

#include <array>
#include <cmath>

namespace kiln {

// A fit's largest error that still rounds like pow to 8 bits but for values within
// a quarter of a step of a rounding boundary.
inline constexpr double kGammaFitTolerance = 1e-3;

struct GammaFit {
    std::array<float, 4> c{};  // of s, s², s³, s⁴
    double maxError = 0.0;     // over x in [0, 1], against pow(x, 1/γ)
    bool usable() const { return maxError <= kGammaFitTolerance; }
};

// Least squares over 2 001 values of s in [0, 1] (the normal equations, 4 × 4), the
// error then measured over 20 001 values of x.
inline GammaFit fitGamma(double gamma) {
    const double a = 4.0 / gamma;
    double m[4][5] = {};
    for (int i = 0; i <= 2000; ++i) {
        const double s = i / 2000.0, y = std::pow(s, a);
        const double p[4] = {s, s * s, s * s * s, s * s * s * s};
        for (int r = 0; r < 4; ++r) {
            for (int c = 0; c < 4; ++c) m[r][c] += p[r] * p[c];
            m[r][4] += p[r] * y;
        }
    }
    for (int col = 0; col < 4; ++col) {  // Gauss–Jordan with partial pivoting
        int pivot = col;
        for (int r = col + 1; r < 4; ++r)
            if (std::abs(m[r][col]) > std::abs(m[pivot][col])) pivot = r;
        for (int c = 0; c < 5; ++c) std::swap(m[col][c], m[pivot][c]);
        for (int r = 0; r < 4; ++r) {
            if (r == col) continue;
            const double f = m[r][col] / m[col][col];
            for (int c = col; c < 5; ++c) m[r][c] -= f * m[col][c];
        }
    }
    GammaFit fit;
    for (int k = 0; k < 4; ++k) fit.c[size_t(k)] = float(m[k][4] / m[k][k]);
    for (int i = 0; i <= 20000; ++i) {
        const double x = i / 20000.0, s = std::sqrt(std::sqrt(x));
        const double v = s * (fit.c[0] + s * (fit.c[1] + s * (fit.c[2] + s * fit.c[3])));
        fit.maxError = std::max(fit.maxError, std::abs(v - std::pow(x, 1.0 / gamma)));
    }
    return fit;
}

}  // namespace kiln
