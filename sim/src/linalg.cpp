// linalg.cpp — small linear algebra: segment distance and the effective-mass solve
// (solveImpulse: inverse or pseudo-inverse of a symmetric 3×3).
#include "internal.hpp"

namespace kiln::sim {

double detail::segmentDistance(const Vec3& p0, const Vec3& p1, const Vec3& q0, const Vec3& q1) {
    const Vec3 d1 = p1 - p0, d2 = q1 - q0, r = p0 - q0;
    const double a = glm::dot(d1, d1), e = glm::dot(d2, d2), f = glm::dot(d2, r);
    double s = 0, t = 0;
    if (a <= 1e-24 && e <= 1e-24) return glm::length(r);
    if (a <= 1e-24) {
        t = std::clamp(f / e, 0.0, 1.0);
    } else {
        const double c = glm::dot(d1, r);
        if (e <= 1e-24) {
            s = std::clamp(-c / a, 0.0, 1.0);
        } else {
            const double b = glm::dot(d1, d2), denom = a * e - b * b;
            s = denom > 1e-24 ? std::clamp((b * f - c * e) / denom, 0.0, 1.0) : 0.0;
            t = (b * s + f) / e;
            if (t < 0.0) t = 0.0, s = std::clamp(-c / a, 0.0, 1.0);
            else if (t > 1.0) t = 1.0, s = std::clamp((b - c) / a, 0.0, 1.0);
        }
    }
    return glm::length(p0 + s * d1 - (q0 + t * d2));
}

Vec3 solveImpulse(const Mat3& K, const Vec3& dv) {
    const double tr = K[0][0] + K[1][1] + K[2][2];
    if (!(tr > 0.0) || !std::isfinite(tr)) return Vec3(0.0);
    const double det = glm::determinant(K);
    // Well conditioned relative to its scale (det ~ (tr/3)³ for an isotropic K).
    const double scale = tr / 3.0;
    if (det > 1e-9 * scale * scale * scale) return glm::inverse(K) * dv;
    // (Nearly) singular: the pseudo-inverse through a Jacobi eigen-decomposition,
    // dropping eigenvalues below 1e-9·λ_max — the minimum-norm least-squares impulse.
    double a[3][3];
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) a[r][c] = 0.5 * (K[c][r] + K[r][c]);
    double v[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    for (int sweep = 0; sweep < 50; ++sweep) {
        const double off = a[0][1] * a[0][1] + a[0][2] * a[0][2] + a[1][2] * a[1][2];
        if (off < 1e-30 * tr * tr) break;
        for (int p = 0; p < 2; ++p)
            for (int q = p + 1; q < 3; ++q) {
                if (a[p][q] == 0.0) continue;
                const double theta = 0.5 * (a[q][q] - a[p][p]) / a[p][q];
                const double t = (theta >= 0 ? 1.0 : -1.0) / (std::abs(theta) + std::sqrt(theta * theta + 1.0));
                const double c = 1.0 / std::sqrt(t * t + 1.0), sn = t * c;
                for (int k = 0; k < 3; ++k) {  // A ← Jᵀ A J
                    const double akp = a[k][p], akq = a[k][q];
                    a[k][p] = c * akp - sn * akq;
                    a[k][q] = sn * akp + c * akq;
                }
                for (int k = 0; k < 3; ++k) {
                    const double apk = a[p][k], aqk = a[q][k];
                    a[p][k] = c * apk - sn * aqk;
                    a[q][k] = sn * apk + c * aqk;
                }
                for (int k = 0; k < 3; ++k) {  // V ← V J
                    const double vkp = v[k][p], vkq = v[k][q];
                    v[k][p] = c * vkp - sn * vkq;
                    v[k][q] = sn * vkp + c * vkq;
                }
            }
    }
    const double lmax = std::max({a[0][0], a[1][1], a[2][2]});
    Vec3 j(0.0);
    for (int e = 0; e < 3; ++e) {
        const double lambda = a[e][e];
        if (!(lambda > 1e-9 * lmax)) continue;
        const Vec3 ve(v[0][e], v[1][e], v[2][e]);
        j += (glm::dot(ve, dv) / lambda) * ve;
    }
    return j;
}
}  // namespace kiln::sim
