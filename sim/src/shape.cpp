#include "kiln/sim/shape.hpp"

#include <algorithm>
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

double RoundCone::sdfWorld(const Vec3& p, const Vec3& position, const Quat& q) const {
    return sdf(glm::inverse(q) * (p - position));
}

Vec3 RoundCone::gradientWorld(const Vec3& p, const Vec3& position, const Quat& q) const {
    return q * gradient(glm::inverse(q) * (p - position));
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

namespace {

// Distance from x to the round cone a0→a1 (radii r0, r1) and the axis parameter u of
// the ball B(P(u), r(u)) that realises it (its surface holds the nearest point).
double coneDistance(const Vec3& x, const Vec3& a0, const Vec3& a1, double r0, double r1, double& u) {
    if (r1 > r0) {  // work with the larger sphere first, then map u back
        const double d = coneDistance(x, a1, a0, r1, r0, u);
        u = 1.0 - u;
        return d;
    }
    Vec3 axis = a1 - a0;
    const double h = glm::length(axis);
    if (h < 1e-12 || r0 - r1 >= h) {  // one sphere contains the other
        u = 0.0;
        return glm::length(x - a0) - r0;
    }
    axis /= h;
    const Vec3 d = x - a0;
    const double y = glm::dot(d, axis);
    const double r = glm::length(d - y * axis);
    const double s = (r0 - r1) / h, c = std::sqrt(1.0 - s * s);
    const double k = y * c - r * s;
    if (k < 0.0) {
        u = 0.0;
        return std::sqrt(r * r + y * y) - r0;
    }
    if (k > c * h) {
        u = 1.0;
        return std::sqrt(r * r + (y - h) * (y - h)) - r1;
    }
    // Side: the normal through x meets the axis at y − r·tan α.
    u = std::clamp((y - r * s / c) / h, 0.0, 1.0);
    return r * c + y * s - r0;
}

}  // namespace

double roundConeDistance(const Vec3& x, const Vec3& a0, const Vec3& a1, double r0, double r1) {
    double u;
    return coneDistance(x, a0, a1, r0, r1, u);
}

ConeSeparation roundConeSeparation(const Vec3& a0, const Vec3& a1, double ra0, double ra1, const Vec3& b0,
                                   const Vec3& b1, double rb0, double rb1) {
    // g(s) = min_u f(s, u) = dist(P_A(s), B) − r_A(s) is convex (a partial minimum of a
    // jointly convex function): golden-section search on s, closed form for u.
    auto g = [&](double s) {
        double u;
        return coneDistance(a0 + s * (a1 - a0), b0, b1, rb0, rb1, u) - (ra0 + s * (ra1 - ra0));
    };
    const double phi = 0.6180339887498949;
    double lo = 0.0, hi = 1.0;
    double x1 = hi - phi * (hi - lo), x2 = lo + phi * (hi - lo), f1 = g(x1), f2 = g(x2);
    for (int i = 0; i < 64; ++i) {  // 0.618^64 ≈ 4e-14 of the axis
        if (f1 < f2) {
            hi = x2, x2 = x1, f2 = f1, x1 = hi - phi * (hi - lo), f1 = g(x1);
        } else {
            lo = x1, x1 = x2, f1 = f2, x2 = lo + phi * (hi - lo), f2 = g(x2);
        }
    }
    ConeSeparation r;
    r.s = 0.5 * (lo + hi);
    double best = g(r.s);
    for (double end : {0.0, 1.0}) {  // the minimum may sit on an end (flat or monotone g)
        const double ge = g(end);
        if (ge < best) best = ge, r.s = end;
    }
    r.onA = a0 + r.s * (a1 - a0);
    r.distance = coneDistance(r.onA, b0, b1, rb0, rb1, r.u) - (ra0 + r.s * (ra1 - ra0));
    r.onB = b0 + r.u * (b1 - b0);
    Vec3 d = r.onB - r.onA;
    double len = glm::length(d);
    if (len < 1e-12) {  // axes meet: no preferred direction; use the base centres, then x
        d = b0 - a0;
        len = glm::length(d);
        if (len < 1e-12) d = Vec3(1, 0, 0), len = 1.0;
    }
    r.normal = d / len;
    r.witnessA = r.onA + (ra0 + r.s * (ra1 - ra0)) * r.normal;
    r.witnessB = r.onB - (rb0 + r.u * (rb1 - rb0)) * r.normal;
    return r;
}

double fourSphereSeparation(const Vec3& a0, const Vec3& a1, double ra0, double ra1, const Vec3& b0,
                            const Vec3& b1, double rb0, double rb1) {
    return std::min({roundConeDistance(a0, b0, b1, rb0, rb1) - ra0, roundConeDistance(a1, b0, b1, rb0, rb1) - ra1,
                     roundConeDistance(b0, a0, a1, ra0, ra1) - rb0, roundConeDistance(b1, a0, a1, ra0, ra1) - rb1});
}

}  // namespace kiln::sim
