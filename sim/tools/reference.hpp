// Independent references for the benchmark (not the sim's integrator): the exact rocking
// period of a ballasted round cone rolling on its lower sphere by quadrature (docs/physics.md §3),
// and the sim's measured period by Hermite-interpolated zero crossings.
#pragma once

#include <cmath>
#include <vector>

#include "kiln/sim/world.hpp"

namespace reference {

// T(θ₀) = 4∫₀^{π/2} √(J(θ)/(mgh)) / √(1 − k² sin²φ) dφ with sin(θ/2) = k·sin φ and
// J(θ) = I_G + m(R² + h² − 2Rh·cos θ); trapezoidal rule over a full period of the smooth
// periodic integrand (spectral accuracy: 4096 points reach rounding).
inline double rockingPeriod(double m, double R, double h, double IG, double g, double th0) {
    const double k = std::sin(0.5 * th0);
    const int n = 4096;
    double sum = 0.0;
    for (int i = 0; i < n; ++i) {
        const double phi = M_PI * i / n, sp = k * std::sin(phi), th = 2.0 * std::asin(sp);
        sum += std::sqrt((IG + m * (R * R + h * h - 2.0 * R * h * std::cos(th))) / (m * g * h)) / std::sqrt(1.0 - sp * sp);
    }
    return 2.0 * sum * (M_PI / n);
}

// Root of the cubic Hermite interpolant of (y, y') on [t0, t0 + dt], y0 < 0 ≤ y1.
inline double hermiteRoot(double t0, double dt, double y0, double d0, double y1, double d1) {
    double lo = 0.0, hi = 1.0;
    for (int it = 0; it < 80; ++it) {
        const double s = 0.5 * (lo + hi);
        const double v = (2 * s * s * s - 3 * s * s + 1) * y0 + (s * s * s - 2 * s * s + s) * dt * d0 +
                         (-2 * s * s * s + 3 * s * s) * y1 + (s * s * s - s * s) * dt * d1;
        (v < 0.0 ? lo : hi) = s;
    }
    return t0 + 0.5 * (lo + hi) * dt;
}

// The world's first tumbler rocking about z: mean spacing of the upward zero crossings
// of its tilt over `seconds`.
inline double measuredPeriod(kiln::sim::World& w, double seconds) {
    auto tilt = [&] {
        const kiln::sim::Vec3 a = w.tumblers()[0].axis();
        return std::atan2(-a.x, a.y);
    };
    const double dt = w.scene().physics.dt;
    std::vector<double> crossings;
    double th = tilt(), om = w.tumblers()[0].angularVelocity.z, t = w.time();
    while (w.time() < seconds) {
        w.step();
        const double th1 = tilt(), om1 = w.tumblers()[0].angularVelocity.z;
        if (th < 0.0 && th1 >= 0.0) crossings.push_back(hermiteRoot(t, dt, th, om, th1, om1));
        th = th1, om = om1, t = w.time();
    }
    if (crossings.size() < 2) return NAN;
    return (crossings.back() - crossings.front()) / double(crossings.size() - 1);
}

}  // namespace reference
