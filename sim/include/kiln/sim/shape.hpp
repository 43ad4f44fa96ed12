// kiln/sim/shape.hpp — the tumbler's shape: a round cone (the convex hull of a lower
// sphere of radius b at the local origin and an upper sphere of radius t at
// (0, y_t, 0), y_t = (b − t)/sin α), its exact signed distance and gradient, and its
// mass properties in closed form (spherical caps + frustum) and by quadrature.
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

    // Radius of the solid at height y (SPEC §3.1); 0 outside [−b, y_t + t].
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

private:
    double b_, t_, alpha_, s_, c_, yt_;
};

}  // namespace kiln::sim
