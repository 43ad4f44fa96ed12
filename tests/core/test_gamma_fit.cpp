// kiln/gamma_fit.hpp: the display gamma as a polynomial in x^(1/4), against std::pow.
#include <catch2/catch.hpp>

#include <cmath>
#include <random>

#include "kiln/gamma_fit.hpp"

TEST_CASE("the gamma fit is within its tolerance of pow where it is used, and refused where not", "[core][tonemap]") {
    // Random x, as float (the shader's precision): the fit's own grid does not pick them.
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    auto worst = [&](const kiln::GammaFit& f, double gamma) {
        double w = 0.0;
        for (int i = 0; i < 100000; ++i) {
            const double x = i < 1000 ? i / 999.0 * 1e-3 : unit(rng);  // the steep start, then anywhere
            const float s = std::sqrt(std::sqrt(float(x)));
            const float v = s * (f.c[0] + s * (f.c[1] + s * (f.c[2] + s * f.c[3])));
            w = std::max(w, std::abs(double(v) - std::pow(x, 1.0 / gamma)));
        }
        return w;
    };
    // 2.2 (the default): measured 5.2e-4 in doubles, 6.1e-4 in floats, a sixth of an
    // 8-bit step; the tolerance 1e-3.
    const kiln::GammaFit fit = kiln::fitGamma(2.2);
    CHECK(fit.usable());
    CHECK(fit.maxError < 6e-4);
    CHECK(worst(fit, 2.2) < 7e-4);
    // γ = 1 and 2 are s⁴ and s² exactly (float rounding aside).
    CHECK(worst(kiln::fitGamma(1.0), 1.0) < 1e-6);
    CHECK(worst(kiln::fitGamma(2.0), 2.0) < 1e-6);
    // Beyond about 2.35 four terms fall short of s^(4/γ)'s steep start: refused (pow).
    const kiln::GammaFit steep = kiln::fitGamma(3.0);
    CHECK_FALSE(steep.usable());
    CHECK(worst(steep, 3.0) > kiln::kGammaFitTolerance);
    // Where usable, its measured error stands for the random points' too.
    for (double gamma = 1.0; gamma <= 3.0; gamma += 0.1) {
        const kiln::GammaFit f = kiln::fitGamma(gamma);
        INFO("gamma " << gamma << ": fit's error " << f.maxError);
        if (f.usable()) CHECK(worst(f, gamma) <= kiln::kGammaFitTolerance * 1.01);
    }
}
