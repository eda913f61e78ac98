// triangle_solid_angle: the signed solid angle of a triangle seen from a point
// (Van Oosterom and Strackee, "The Solid Angle of a Plane Triangle", 1983).
//
// Inputs: query point q, triangle (a, b, c), any units. Output: the signed solid angle in
//   steradians, in (-2 pi, 2 pi): positive when q lies behind the triangle, i.e. on the side
//   its normal (b - a) x (c - a) points away from. Summed over a closed, outward-oriented
//   mesh and divided by 4 pi it is the winding number (1 inside, 0 outside).
//   Exactly 0 when q lies in the triangle's plane (also for degenerate triangles), so points on
//   the surface get the mean of the two sides.
// Cost: ~40 flops and one atan2. Threading: pure. Errors: none.
// polynomial_atan2(y, x): atan2 without branches (selects only, so that loops over it
//   vectorise), |error| < 2e-8; 0 for y == 0 (as the exact solid angle's 0 in the plane).
// fast_triangle_solid_angle: triangle_solid_angle with it (|error| < 4e-8 sr), ~3x cheaper.
#pragma once

#include <algorithm>
#include <cmath>

#include "core/vec3.hpp"

namespace levelset {

inline double triangle_solid_angle(const Vec3d& q, const Vec3d& a, const Vec3d& b, const Vec3d& c) {
  const Vec3d x = a - q, y = b - q, z = c - q;
  const double det = dot(x, cross(y, z));
  if (det == 0.0) return 0.0;
  const double lx = length(x), ly = length(y), lz = length(z);
  const double denom = lx * ly * lz + dot(x, y) * lz + dot(y, z) * lx + dot(z, x) * ly;
  return 2.0 * std::atan2(det, denom);
}

// The octant reduction to t = min / max in [0, 1], then t > tan(pi / 8) shifted by pi / 4 to
// |u| <= tan(pi / 8), where the Taylor series to u^15 is within 2e-8.
inline double polynomial_atan2(double y, double x) {
  constexpr double kTanPi8 = 0.41421356237309503;
  constexpr double kPi = 3.14159265358979323846;
  const double ay = std::abs(y), ax = std::abs(x);
  const double hi = std::max(ax, ay), lo = std::min(ax, ay);
  const double t = hi > 0.0 ? lo / hi : 0.0;
  const bool shifted = t > kTanPi8;
  const double u = shifted ? (t - 1.0) / (t + 1.0) : t;
  const double u2 = u * u;
  const double series =
      u * (1.0 + u2 * (-1.0 / 3 + u2 * (1.0 / 5 + u2 * (-1.0 / 7 + u2 * (1.0 / 9 + u2 * (-1.0 / 11 +
           u2 * (1.0 / 13 + u2 * (-1.0 / 15))))))));
  double r = (shifted ? 0.25 * kPi : 0.0) + series;
  r = ay > ax ? 0.5 * kPi - r : r;
  r = x < 0.0 ? kPi - r : r;
  r = y < 0.0 ? -r : r;
  return y == 0.0 ? 0.0 : r;
}

inline double fast_triangle_solid_angle(const Vec3d& q, const Vec3d& a, const Vec3d& b,
                                        const Vec3d& c) {
  const Vec3d x = a - q, y = b - q, z = c - q;
  const double det = dot(x, cross(y, z));
  const double lx = length(x), ly = length(y), lz = length(z);
  const double denom = lx * ly * lz + dot(x, y) * lz + dot(y, z) * lx + dot(z, x) * ly;
  return 2.0 * polynomial_atan2(det, denom);
}

}  // namespace levelset
