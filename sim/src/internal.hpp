// internal.hpp — helpers shared by libkiln_sim's sources (not installed, not API).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

#include "kiln/sim/world.hpp"

namespace kiln::sim::detail {

inline constexpr double kPi = 3.14159265358979323846;
inline constexpr double kFireRate = 400.0;  // particles per second per fireball (docs/physics.md §6)
inline constexpr double kFireLife = 0.45;

// [r]× as a column-major glm matrix: skew(r) * v == cross(r, v).
inline Mat3 skew(const Vec3& r) { return Mat3(0, r.z, -r.y, -r.z, 0, r.x, r.y, -r.x, 0); }

// Distance between segments p0p1 and q0q1 (Ericson, Real-Time Collision Detection 5.1.9).
double segmentDistance(const Vec3& p0, const Vec3& p1, const Vec3& q0, const Vec3& q1);

}  // namespace kiln::sim::detail
