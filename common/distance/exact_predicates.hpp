// Exact orientation predicates for the sign tests of the distance code (after Shewchuk,
// "Adaptive Precision Floating-Point Arithmetic and Fast Robust Geometric Predicates", 1997).
//
// Inputs: double coordinates (any units). Outputs: the exact sign (-1, 0, +1) of
//   orient2d(a, b, c) = (ax - cx)(by - cy) - (ay - cy)(bx - cx)   (> 0: a, b, c counterclockwise)
//   orient3d(a, b, c, d) = (a - d) . ((b - d) x (c - d))            (> 0: d behind the plane of a,
//   b,
//                                                                     c, which turn
//                                                                     counterclockwise seen from
//                                                                     the front)
// Method: the caller (or the *_sign helpers) evaluates the determinant in doubles exactly as
//   written above and trusts its sign when |det| exceeds the static bound times the permanent
//   (kOrient2dErrorBound, kOrient3dErrorBound); otherwise the *_exact functions recompute it in
//   floating-point expansion arithmetic (error-free two_sum / fma two_product), which is exact.
// Assumptions: no overflow or underflow in the intermediate products (coordinates between
//   about 1e-100 and 1e100 in magnitude, or zero).
// Cost: the filtered path is ~20 (2D) / ~40 (3D) flops; the exact path works on the stack
//   (no allocation) and costs well under a microsecond, and runs only for (nearly) degenerate inputs.
// Threading: pure functions. Errors: none (non-finite inputs give an unspecified sign).
#pragma once

#include "core/vec3.hpp"

namespace levelset {

inline constexpr double kUnitRoundoff = 1.1102230246251565e-16;  // 2^-53
inline constexpr double kOrient2dErrorBound = (3.0 + 16.0 * kUnitRoundoff) * kUnitRoundoff;
inline constexpr double kOrient3dErrorBound = (7.0 + 56.0 * kUnitRoundoff) * kUnitRoundoff;

int orient2d_exact(double ax, double ay, double bx, double by, double cx, double cy);
int orient3d_exact(const Vec3d& a, const Vec3d& b, const Vec3d& c, const Vec3d& d);

// Filtered exact sign of orient2d.
inline int orient2d_sign(double ax, double ay, double bx, double by, double cx, double cy) {
  const double left = (ax - cx) * (by - cy);
  const double right = (ay - cy) * (bx - cx);
  const double det = left - right;
  const double bound =
      kOrient2dErrorBound * ((left < 0 ? -left : left) + (right < 0 ? -right : right));
  if (det > bound) return 1;
  if (-det > bound) return -1;
  return orient2d_exact(ax, ay, bx, by, cx, cy);
}

// Filtered exact sign of orient3d.
inline int orient3d_sign(const Vec3d& a, const Vec3d& b, const Vec3d& c, const Vec3d& d) {
  const double adx = a.x - d.x, ady = a.y - d.y, adz = a.z - d.z;
  const double bdx = b.x - d.x, bdy = b.y - d.y, bdz = b.z - d.z;
  const double cdx = c.x - d.x, cdy = c.y - d.y, cdz = c.z - d.z;
  const double bc = bdx * cdy, cb = cdx * bdy;
  const double ca = cdx * ady, ac = adx * cdy;
  const double ab = adx * bdy, ba = bdx * ady;
  const double det = adz * (bc - cb) + bdz * (ca - ac) + cdz * (ab - ba);
  auto abs = [](double v) { return v < 0 ? -v : v; };
  const double permanent = (abs(bc) + abs(cb)) * abs(adz) + (abs(ca) + abs(ac)) * abs(bdz) +
                           (abs(ab) + abs(ba)) * abs(cdz);
  const double bound = kOrient3dErrorBound * permanent;
  if (det > bound) return 1;
  if (-det > bound) return -1;
  return orient3d_exact(a, b, c, d);
}

}  // namespace levelset
