#include "kiln/sim/shape.hpp"

#include <array>
#include <cmath>
#include <vector>

namespace kiln::sim {

namespace {
constexpr double kPi = 3.14159265358979323846;

// A polynomial in y, lowest degree first: enough algebra for exact volume integrals.
using Poly = std::vector<double>;
Poly mul(const Poly& a, const Poly& b) {
    Poly r(a.size() + b.size() - 1, 0.0);
    for (size_t i = 0; i < a.size(); ++i)
        for (size_t j = 0; j < b.size(); ++j) r[i + j] += a[i] * b[j];
    return r;
}
double integrate(const Poly& p, double y0, double y1) {
    double s = 0.0;
    for (size_t k = 0; k < p.size(); ++k)
        s += p[k] * (std::pow(y1, double(k + 1)) - std::pow(y0, double(k + 1))) / double(k + 1);
    return s;
}

struct Moments {  // ∫R², ∫yR², ∫y²R², ∫R⁴ over the height
    double r2 = 0, yr2 = 0, y2r2 = 0, r4 = 0;
};

MassProperties fromMoments(const Moments& m, double mass) {
    MassProperties p;
    p.volume = kPi * m.r2;
    p.density = mass / p.volume;
    p.comY = kPi * m.yr2 / p.volume;
    const double ixx = p.density * (kPi / 4.0) * (m.r4 + 4.0 * m.y2r2);
    const double iyy = p.density * (kPi / 2.0) * m.r4;
    p.inertiaOrigin = {ixx, iyy, ixx};
    const double shift = mass * p.comY * p.comY;  // parallel axis, x and z only
    p.inertiaCom = {ixx - shift, iyy, ixx - shift};
    return p;
}
}  // namespace

RoundCone::RoundCone(double b, double t, double alpha)
    : b_(b), t_(t), alpha_(alpha), s_(std::sin(alpha)), c_(std::cos(alpha)), yt_((b - t) / std::sin(alpha)) {}

double RoundCone::radiusAt(double y) const {
    if (y < -b_ || y > yt_ + t_) return 0.0;
    if (y < b_ * s_) return std::sqrt(std::max(0.0, b_ * b_ - y * y));
    if (y <= yt_ + t_ * s_) return -y * s_ / c_ + b_ / c_;
    const double u = y - yt_;
    return std::sqrt(std::max(0.0, t_ * t_ - u * u));
}

double RoundCone::sdf(const Vec3& p) const {
    const double r = std::sqrt(p.x * p.x + p.z * p.z);
    const double k = p.y * c_ - r * s_;  // position along the side line
    if (k < 0.0) return std::sqrt(r * r + p.y * p.y) - b_;
    if (k > yt_ * c_) return std::sqrt(r * r + (p.y - yt_) * (p.y - yt_)) - t_;
    return p.y * s_ + r * c_ - b_;
}

Vec3 RoundCone::gradient(const Vec3& p) const {
    const double r = std::sqrt(p.x * p.x + p.z * p.z);
    const double k = p.y * c_ - r * s_;
    if (k < 0.0) {
        const double len = glm::length(p);
        return len > 1e-300 ? p / len : Vec3(0, -1, 0);
    }
    if (k > yt_ * c_) {
        const Vec3 d = p - Vec3(0, yt_, 0);
        const double len = glm::length(d);
        return len > 1e-300 ? d / len : Vec3(0, 1, 0);
    }
    if (r < 1e-300) return Vec3(0, 1, 0);  // on the axis inside: no unique side normal
    return {c_ * p.x / r, s_, c_ * p.z / r};
}

MassProperties RoundCone::massProperties(double mass) const {
    // R² per piece as a quadratic in y.
    const double ts = yt_ + t_ * s_;
    const std::array<std::pair<Poly, std::array<double, 2>>, 3> pieces = {{
        {{b_ * b_, 0.0, -1.0}, {-b_, b_ * s_}},                                       // lower cap
        {{b_ * b_ / (c_ * c_), -2.0 * b_ * s_ / (c_ * c_), s_ * s_ / (c_ * c_)}, {b_ * s_, ts}},  // frustum
        {{t_ * t_ - yt_ * yt_, 2.0 * yt_, -1.0}, {ts, yt_ + t_}},                     // upper cap
    }};
    Moments m;
    for (auto& [r2, range] : pieces) {
        m.r2 += integrate(r2, range[0], range[1]);
        m.yr2 += integrate(mul(r2, {0.0, 1.0}), range[0], range[1]);
        m.y2r2 += integrate(mul(r2, {0.0, 0.0, 1.0}), range[0], range[1]);
        m.r4 += integrate(mul(r2, r2), range[0], range[1]);
    }
    return fromMoments(m, mass);
}

MassProperties RoundCone::integratedMassProperties(double mass, int intervals) const {
    // 5-point Gauss–Legendre on sub-intervals of each piece, sampling radiusAt().
    static const double x[5] = {0.0, -0.5384693101056831, 0.5384693101056831, -0.9061798459386640, 0.9061798459386640};
    static const double w[5] = {0.5688888888888889, 0.4786286704993665, 0.4786286704993665, 0.2369268850561891,
                                0.2369268850561891};
    const double breaks[4] = {-b_, b_ * s_, yt_ + t_ * s_, yt_ + t_};
    Moments m;
    for (int piece = 0; piece < 3; ++piece) {
        const double h = (breaks[piece + 1] - breaks[piece]) / intervals;
        for (int i = 0; i < intervals; ++i) {
            const double mid = breaks[piece] + (i + 0.5) * h;
            for (int k = 0; k < 5; ++k) {
                const double y = mid + 0.5 * h * x[k], wk = 0.5 * h * w[k];
                const double r2 = radiusAt(y) * radiusAt(y);
                m.r2 += wk * r2;
                m.yr2 += wk * y * r2;
                m.y2r2 += wk * y * y * r2;
                m.r4 += wk * r2 * r2;
            }
        }
    }
    return fromMoments(m, mass);
}

}  // namespace kiln::sim
