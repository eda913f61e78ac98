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
#pragma once

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

}  // namespace levelset
