// kiln/sim/shape.hpp — the tumbler's shape: a round cone (the convex hull of a lower
// sphere of radius b at the local origin and an upper sphere of radius t at
// (0, y_t, 0), y_t = (b − t)/sin α), its exact signed distance and gradient, and its
// mass properties in closed form (spherical caps + frustum) and by quadrature.
//
// SDF (docs/physics.md §1, Quilez's sdRoundCone): with r = √(x²+z²), k = y·cos α − r·sin α:
//   k < 0            → lower sphere   √(r² + y²) − b
//   k > y_t·cos α    → upper sphere   √(r² + (y − y_t)²) − t     ([fix]: not y_t / tan α)
//   otherwise        → side           y·sin α + r·cos α − b
// It is exact inside and outside. The gradient is the outward normal of the nearest
// piece; on the axis inside the side region (no unique normal) it returns +y.
//
// Also here: the exact separation of two round cones (tumbler vs tumbler), minimising
// |P_A(s) − P_B(u)| − r_A(s) − r_B(u) over s, u ∈ [0, 1] (jointly convex).
#pragma once

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

namespace kiln::sim {

using Vec3 = glm::dvec3;
using Quat = glm::dquat;
using Mat3 = glm::dmat3;

struct MassProperties {
    double volume = 0, density = 0;
    double comY = 0;           // centre of mass on the axis, above the lower-sphere centre
    Vec3 inertiaOrigin{0.0};   // diagonal inertia about the lower-sphere centre
    Vec3 inertiaCom{0.0};      // diagonal inertia about the centre of mass
};

class RoundCone {
public:
    RoundCone(double b = 0.2, double t = 0.1, double alpha = 0.3490658503988659);

    double b() const { return b_; }
    double t() const { return t_; }
    double alpha() const { return alpha_; }
    double upperCentre() const { return yt_; }  // y_t
    double top() const { return yt_ + t_; }

    // Radius of the solid at height y (docs/physics.md §1); 0 outside [−b, y_t + t].
    double radiusAt(double y) const;
    // Exact signed distance in local space (negative inside).
    double sdf(const Vec3& p) const;
    // Outward unit normal of the nearest surface piece. Undefined only on the axis
    // between the centres deeper than t; there it returns +y (treat as tunnelling).
    Vec3 gradient(const Vec3& p) const;

    // Uniform density, total mass `mass`: exact polynomial integrals per piece.
    MassProperties massProperties(double mass) const;
    // The same by Gauss–Legendre quadrature of radiusAt() (a cross-check).
    MassProperties integratedMassProperties(double mass, int intervalsPerPiece = 64) const;

    // World-space versions for a body at `position` (the local origin O) with
    // orientation `q`: the point goes to local space, the normal comes back rotated.
    double sdfWorld(const Vec3& p, const Vec3& position, const Quat& q) const;
    Vec3 gradientWorld(const Vec3& p, const Vec3& position, const Quat& q) const;

private:
    double b_, t_, alpha_, s_, c_, yt_;
};

// Exact signed distance from x to the round cone with axis a0 → a1 and end radii r0, r1
// (any orientation; equals min over u of |x − P(u)| − r(u), inside too).
double roundConeDistance(const Vec3& x, const Vec3& a0, const Vec3& a1, double r0, double r1);

// Exact separation of two round cones A (a0→a1, radii ra0, ra1) and B: the minimum
// over s, u ∈ [0,1] of |P_A(s) − P_B(u)| − r_A(s) − r_B(u) (negative: they overlap by
// that much along `normal`). The function is jointly convex, so the nested 1-D
// minimisation (golden section on s, the closed-form round-cone distance for u) finds
// the global minimum.
struct ConeSeparation {
    double distance = 0;
    double s = 0, u = 0;          // parameters on A's and B's axes
    Vec3 onA{0.0}, onB{0.0};      // the axis points P_A(s), P_B(u)
    Vec3 normal{1, 0, 0};         // unit, from A towards B (a fallback when the axes meet)
    Vec3 witnessA{0.0}, witnessB{0.0};  // surface points P_A + r_A·n and P_B − r_B·n
};
ConeSeparation roundConeSeparation(const Vec3& a0, const Vec3& a1, double ra0, double ra1, const Vec3& b0,
                                   const Vec3& b1, double rb0, double rb1);

// The course design's approximation (four end spheres, each against the other body's exact
// SDF): min of SDF_B(a0) − ra0, SDF_B(a1) − ra1, SDF_A(b0) − rb0, SDF_A(b1) − rb1.
// Never below the exact separation (each end sphere is a subset of its body).
double fourSphereSeparation(const Vec3& a0, const Vec3& a1, double ra0, double ra1, const Vec3& b0,
                            const Vec3& b1, double rb0, double rb1);

}  // namespace kiln::sim
