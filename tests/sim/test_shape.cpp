// The tumbler's shape: SDF against a brute-force distance, gradient, mass properties.
#include <catch2/catch.hpp>

#include <cmath>

#include "kiln/sim/shape.hpp"
#include "kiln/sim/world.hpp"

using namespace kiln::sim;

namespace {

// Brute force: the distance from (r, y) to the profile curve (lower arc, side
// segment, upper arc) in the meridian half-plane, by dense sampling of each piece and
// a golden-section refinement; the opposite meridian (−r) is checked too. The sign
// comes from comparing r with the radius profile.
double bruteDistance(const RoundCone& s, const Vec3& p) {
    const double b = s.b(), t = s.t(), a = s.alpha(), yt = s.upperCentre();
    auto lower = [&](double u) {  // latitude from −π/2 to α
        double lat = -M_PI / 2 + u * (a + M_PI / 2);
        return glm::dvec2(b * std::cos(lat), b * std::sin(lat));
    };
    auto side = [&](double u) { return glm::mix(lower(1.0), glm::dvec2(t * std::cos(a), yt + t * std::sin(a)), u); };
    auto upper = [&](double u) {
        double lat = a + u * (M_PI / 2 - a);
        return glm::dvec2(t * std::cos(lat), yt + t * std::sin(lat));
    };
    const double r = std::sqrt(p.x * p.x + p.z * p.z);
    double best = 1e9;
    for (double sign : {1.0, -1.0}) {
        const glm::dvec2 q(sign * r, p.y);
        auto piece = [&](auto curve) {
            const int n = 200;
            int bi = 0;
            double bd = 1e9;
            for (int i = 0; i <= n; ++i) {
                double d = glm::length(curve(double(i) / n) - q);
                if (d < bd) bd = d, bi = i;
            }
            double lo = std::max(0.0, (bi - 1.0) / n), hi = std::min(1.0, (bi + 1.0) / n);
            const double g = 0.6180339887498949;
            for (int k = 0; k < 60; ++k) {
                double x1 = hi - g * (hi - lo), x2 = lo + g * (hi - lo);
                if (glm::length(curve(x1) - q) < glm::length(curve(x2) - q)) hi = x2; else lo = x1;
            }
            return std::min(bd, glm::length(curve(0.5 * (lo + hi)) - q));
        };
        best = std::min({best, piece(lower), piece(side), piece(upper)});
    }
    const bool inside = p.y > -b && p.y < yt + t && r < s.radiusAt(p.y);
    return inside ? -best : best;
}

}  // namespace

TEST_CASE("round cone SDF equals the brute-force distance inside and outside", "[sim][shape]") {
    RoundCone s;
    Rng rng(42);
    int inside = 0;
    double worst = 0;
    // 1e-6: the brute force refines to ~1e-12, so anything above 1e-6 is a formula error.
    for (int i = 0; i < 100000; ++i) {
        Vec3 p(rng.uniform(-0.23, 0.23), rng.uniform(-0.23, 0.43), rng.uniform(-0.23, 0.23));
        double d = s.sdf(p);
        worst = std::max(worst, std::abs(d - bruteDistance(s, p)));
        inside += d < 0;
    }
    INFO("worst " << worst << ", inside " << inside);
    CHECK(worst < 1e-6);
    CHECK(inside > 20000);   // both sides were really sampled
    CHECK(inside < 80000);
}

TEST_CASE("round cone gradient is the central difference of the SDF outside", "[sim][shape]") {
    RoundCone s;
    Rng rng(3);
    double worst = 0;
    for (int i = 0; i < 20000; ++i) {
        Vec3 p(rng.uniform(-0.5, 0.5), rng.uniform(-0.4, 0.6), rng.uniform(-0.5, 0.5));
        if (s.sdf(p) < 1e-3) continue;  // the exterior SDF is C¹; inside it has a medial axis
        const double h = 1e-6;
        Vec3 fd((s.sdf(p + Vec3(h, 0, 0)) - s.sdf(p - Vec3(h, 0, 0))) / (2 * h),
                (s.sdf(p + Vec3(0, h, 0)) - s.sdf(p - Vec3(0, h, 0))) / (2 * h),
                (s.sdf(p + Vec3(0, 0, h)) - s.sdf(p - Vec3(0, 0, h))) / (2 * h));
        worst = std::max(worst, glm::length(fd - s.gradient(p)));
    }
    // Central differences with h = 1e-6 in double: truncation ~1e-12/R, rounding ~1e-10.
    CHECK(worst < 1e-5);
}

TEST_CASE("round cone gradient is the central difference of the SDF inside too", "[sim][shape]") {
    RoundCone s;
    Rng rng(4);
    double worst = 0;
    int used = 0;
    for (int i = 0; i < 20000; ++i) {
        Vec3 p(rng.uniform(-0.2, 0.2), rng.uniform(-0.2, 0.4), rng.uniform(-0.2, 0.2));
        if (s.sdf(p) > -1e-3) continue;
        const double h = 1e-6;
        Vec3 fd((s.sdf(p + Vec3(h, 0, 0)) - s.sdf(p - Vec3(h, 0, 0))) / (2 * h),
                (s.sdf(p + Vec3(0, h, 0)) - s.sdf(p - Vec3(0, h, 0))) / (2 * h),
                (s.sdf(p + Vec3(0, 0, h)) - s.sdf(p - Vec3(0, 0, h))) / (2 * h));
        // Inside, the SDF has a medial axis (the cone's axis, and where the pieces meet
        // inside): there the difference straddles two pieces and is not a unit vector.
        // Away from it the gradient must match.
        if (std::abs(glm::length(fd) - 1.0) > 1e-6) continue;
        ++used;
        worst = std::max(worst, glm::length(fd - s.gradient(p)));
    }
    INFO(used << " interior points used");
    CHECK(used > 5000);
    CHECK(worst < 1e-5);  // as outside: truncation ~1e-12, rounding ~1e-10
}

TEST_CASE("SDF and gradient stay finite on the axis and at the sphere centres", "[sim][shape]") {
    RoundCone s;
    for (double y = -0.25; y <= 0.45; y += 0.001) {
        Vec3 p(0, y, 0);
        CHECK(std::isfinite(s.sdf(p)));
        Vec3 g = s.gradient(p);
        CHECK(std::isfinite(g.x + g.y + g.z));
        CHECK(glm::length(g) == Approx(1.0).epsilon(1e-12));
    }
    CHECK(s.sdf(Vec3(0.0)) == Approx(-0.2).epsilon(1e-12));
    CHECK(s.sdf(Vec3(0, s.upperCentre(), 0)) == Approx(-0.1).epsilon(1e-12));
    CHECK(std::isfinite(glm::length(s.gradient(Vec3(0, s.upperCentre(), 0)))));
    CHECK(glm::length(s.gradient(Vec3(0.0))) == Approx(1.0));
    // Radius profile: the three pieces meet continuously.
    const double eps = 1e-12;
    for (double y : {s.b() * std::sin(s.alpha()), s.upperCentre() + s.t() * std::sin(s.alpha())})
        CHECK(s.radiusAt(y - eps) == Approx(s.radiusAt(y + eps)).margin(1e-9));
    CHECK(s.radiusAt(0.0) == Approx(0.2));
    CHECK(s.radiusAt(s.top()) == Approx(0.0).margin(1e-12));
    CHECK(s.radiusAt(s.top() + 0.01) == 0.0);
}

TEST_CASE("the course design's threshold slip is fixed: 1 cm above the top reads +1 cm", "[sim][shape]") {
    RoundCone s;
    CHECK(s.upperCentre() == Approx(0.292380440016).epsilon(1e-11));
    // With the course design's y_t/tan α threshold this read −0.062 (docs/physics.md §1).
    CHECK(s.sdf(Vec3(0, s.top() + 0.01, 0)) == Approx(0.01).margin(1e-12));
    CHECK(s.sdf(Vec3(0, s.top() - 0.01, 0)) == Approx(-0.01).margin(1e-12));
}

TEST_CASE("mass properties: closed form = quadrature = docs/physics.md's table", "[sim][shape]") {
    RoundCone s;
    MassProperties exact = s.massProperties(1.0), quad = s.integratedMassProperties(1.0);
    auto rel = [](double a, double b) { return std::abs(a - b) / std::abs(b); };
    // Quadrature of polynomial pieces is exact up to rounding: 1e-9 relative is loose.
    CHECK(rel(quad.volume, exact.volume) < 1e-9);
    CHECK(rel(quad.comY, exact.comY) < 1e-9);
    for (int k = 0; k < 3; ++k) {
        CHECK(rel(quad.inertiaOrigin[k], exact.inertiaOrigin[k]) < 1e-9);
        CHECK(rel(quad.inertiaCom[k], exact.inertiaCom[k]) < 1e-9);
    }
    // Independent values (docs/physics.md §2), given to 12 digits.
    CHECK(rel(exact.volume, 0.0427893001736) < 1e-10);
    CHECK(rel(exact.density, 23.3703284686) < 1e-10);
    CHECK(rel(exact.comY, 0.0521160345185) < 1e-10);
    CHECK(rel(exact.inertiaOrigin.x, 0.0269892227236) < 1e-10);
    CHECK(rel(exact.inertiaOrigin.y, 0.0146421435034) < 1e-10);
    CHECK(rel(exact.inertiaCom.x, 0.0242731416696) < 1e-10);
}

TEST_CASE("mass properties agree with Monte Carlo over the SDF", "[sim][shape]") {
    RoundCone s;
    Rng rng(9);
    const int n = 400000;
    int hits = 0;
    double sy = 0, syy = 0, sxx = 0;
    // Box [-0.2,0.2] × [-0.2,0.4] × [-0.2,0.2] holds the whole tumbler.
    for (int i = 0; i < n; ++i) {
        Vec3 p(rng.uniform(-0.2, 0.2), rng.uniform(-0.2, 0.4), rng.uniform(-0.2, 0.2));
        if (s.sdf(p) > 0) continue;
        ++hits, sy += p.y, syy += p.y * p.y, sxx += p.x * p.x;
    }
    const double volume = 0.4 * 0.6 * 0.4 * hits / n;
    MassProperties exact = s.massProperties(1.0);
    // ~170k inside samples: relative standard error ≈ 0.2 %; 1 % is a 5σ bound.
    CHECK(volume == Approx(exact.volume).epsilon(0.01));
    CHECK(sy / hits == Approx(exact.comY).epsilon(0.02));
    // I_yy about the axis = m·E[x² + z²] = 2 m E[x²].
    CHECK(2.0 * sxx / hits == Approx(exact.inertiaOrigin.y).epsilon(0.01));
}
