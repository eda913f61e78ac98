// The smallest eigenpair of a symmetric 3x3 matrix | a d e ; d b f ; e f c |, closed form
// (trigonometric, after Smith 1961): the plane fits' normal and residual. O(1), reentrant.
// A repeated smallest eigenvalue has no unique eigenvector: any unit vector of its space.
#pragma once

#include <algorithm>
#include <cmath>
#include <numbers>

#include "core/vec3.hpp"

namespace levelset {

inline double smallest_eigenvalue(double a, double b, double c, double d, double e, double f) {
  const double p1 = d * d + e * e + f * f;
  const double q = (a + b + c) / 3.0;
  if (p1 <= 1e-300) return std::min({a, b, c});
  const double p2 = (a - q) * (a - q) + (b - q) * (b - q) + (c - q) * (c - q) + 2.0 * p1;
  const double p = std::sqrt(p2 / 6.0);
  const double ba = (a - q) / p, bb = (b - q) / p, bc = (c - q) / p, bd = d / p, be = e / p, bf = f / p;
  const double det = ba * (bb * bc - bf * bf) - bd * (bd * bc - bf * be) + be * (bd * bf - bb * be);
  const double r = std::clamp(det / 2.0, -1.0, 1.0);
  const double phi = std::acos(r) / 3.0;
  return q + 2.0 * p * std::cos(phi + 2.0 * std::numbers::pi / 3.0);
}

// A unit eigenvector of `lambda` (an eigenvalue of the matrix): the longest cross product of
// two rows of M - lambda I (they span the plane orthogonal to it).
inline Vec3d eigenvector_of(double a, double b, double c, double d, double e, double f, double lambda) {
  const Vec3d r0{a - lambda, d, e}, r1{d, b - lambda, f}, r2{e, f, c - lambda};
  const Vec3d c01 = cross(r0, r1), c02 = cross(r0, r2), c12 = cross(r1, r2);
  const double l01 = dot(c01, c01), l02 = dot(c02, c02), l12 = dot(c12, c12);
  const Vec3d best = l01 >= l02 && l01 >= l12 ? c01 : (l02 >= l12 ? c02 : c12);
  const double len = std::sqrt(std::max({l01, l02, l12}));
  if (!(len > 0.0)) {  // M - lambda I vanishes (lambda triple) or has rank 1: any vector orthogonal to a row
    const Vec3d row = dot(r0, r0) > 0.0 ? r0 : (dot(r1, r1) > 0.0 ? r1 : r2);
    if (!(dot(row, row) > 0.0)) return {0.0, 0.0, 1.0};
    const Vec3d other = std::abs(row.x) < 0.9 * std::sqrt(dot(row, row)) ? Vec3d{1, 0, 0} : Vec3d{0, 1, 0};
    const Vec3d v = cross(row, other);
    return v / std::sqrt(dot(v, v));
  }
  return best / len;
}

}  // namespace levelset
