// Curvature of the level set through a voxel, from a dense array of samples (thesis 4.4,
// "Curvature Discretization", eq. 4.3-4.5).
//
// Conventions: u is a signed distance-like function, negative inside; n = grad u / |grad u|
//   points outward. Mean curvature H = k1 + k2 = div n (not the average): a sphere of radius r
//   has k1 = k2 = 1/r, H = 2/r, Gaussian curvature K = k1 k2 = 1/r^2; convex is positive.
//   Away from the zero level the answer is the curvature of the level set through the voxel
//   (the thesis's extension of the curvature to the whole domain).
// Inputs: v points at the centre sample of a dense float array (e.g. a gather_tile tile with
//   halo >= 1); v[dx*stride[0] + dy*stride[1] + dz*stride[2]] must be valid for dx, dy, dz in
//   {-1, 0, 1} (19 of the 27 are read: the centre, 6 faces, 12 edges; no corners).
//   h: voxel size in world units (> 0). Values are in value units (world units for a distance).
// Method: gradient by central differences, Hessian by central second differences (mixed terms
//   by the 4-point cross stencil), all in double. curvature_at builds an orthonormal basis
//   (b1, b2) of the tangent plane (b1 = n x e_i, e_i the axis least aligned with n, normalised;
//   b2 = n x b1), M = B^T Hess B / |grad u| (2x2, symmetric) and its eigenvalues in closed form,
//   k1,2 = (a+d)/2 +- sqrt(((a-d)/2)^2 + b^2) (no cubic). mean_curvature_at gives H alone by the
//   trace form H = (|g|^2 tr Hess - g^T Hess g) / |g|^3 (Osher & Fedkiw eq. 1.8), which equals
//   tr M up to rounding (B B^T + n n^T = I).
// Accuracy: second order in h for smooth u (exact for quadratic u); the level set's curvature
//   radius should span several voxels (sphere, r = 10 h: H within 0.4%, K within 0.7%; r = 20 h: 4x
//   less).
// Outputs: Curvature in 1 / world units (k1 >= k2; gauss in 1 / world units^2); grad_norm in
//   value units per world unit (1 for a distance function).
// Degenerate gradient: when |grad u| <= kMinGradNorm (e.g. a constant field, or a skeleton point
//   where the central differences cancel) every output, grad_norm included, is 0 (never NaN or
//   Inf). A gradient just above the threshold gives large but finite curvatures.
// Cost: 19 loads, about 100 flops and 3 square roots (curvature_at) or 1 (mean_curvature_at);
//   no allocation, no branches beyond the degenerate test and the basis axis choice.
// Threading: pure functions of their arguments; thread-safe.
#pragma once

#include <cmath>
#include <cstddef>

#include "core/vec3.hpp"

namespace levelset::evolve {

struct Curvature {
  double grad_norm = 0;   // |grad u| by central differences, value units per world unit
  Vec3d normal{};         // unit outward normal (zero when grad_norm is ~0)
  double mean = 0;        // H = k1 + k2, 1 / world units
  double gauss = 0;       // K = k1 * k2, 1 / world units^2
  double k1 = 0, k2 = 0;  // principal curvatures, k1 >= k2, 1 / world units
};

// Below this |grad u| (value units per world unit) the normal is undefined: outputs are zero.
inline constexpr double kMinGradNorm = 1e-12;

namespace detail {

// Gradient g and symmetric Hessian (xx, yy, zz, xy, xz, yz) by central differences, in world units.
struct Derivs {
  Vec3d g;
  double xx, yy, zz, xy, xz, yz;
};

inline Derivs central_derivs(const float* v, const std::ptrdiff_t stride[3], double h) {
  const std::ptrdiff_t sx = stride[0], sy = stride[1], sz = stride[2];
  const double c = v[0];
  const double xp = v[sx], xm = v[-sx], yp = v[sy], ym = v[-sy], zp = v[sz], zm = v[-sz];
  const double inv2h = 0.5 / h, invh2 = 1.0 / (h * h), inv4h2 = 0.25 * invh2;
  Derivs d;
  d.g = {(xp - xm) * inv2h, (yp - ym) * inv2h, (zp - zm) * inv2h};
  d.xx = (xp - 2.0 * c + xm) * invh2;
  d.yy = (yp - 2.0 * c + ym) * invh2;
  d.zz = (zp - 2.0 * c + zm) * invh2;
  auto cross_term = [&](std::ptrdiff_t a, std::ptrdiff_t b) {
    return ((double(v[a + b]) - double(v[a - b])) - (double(v[-a + b]) - double(v[-a - b]))) *
           inv4h2;
  };
  d.xy = cross_term(sx, sy);
  d.xz = cross_term(sx, sz);
  d.yz = cross_term(sy, sz);
  return d;
}

inline Vec3d hess_times(const Derivs& d, const Vec3d& w) {
  return {d.xx * w.x + d.xy * w.y + d.xz * w.z, d.xy * w.x + d.yy * w.y + d.yz * w.z,
          d.xz * w.x + d.yz * w.y + d.zz * w.z};
}

}  // namespace detail

// Full form: normal, mean, Gaussian and principal curvatures of the level set through v[0].
inline Curvature curvature_at(const float* v, const std::ptrdiff_t stride[3], double h) {
  const detail::Derivs d = detail::central_derivs(v, stride, h);
  const double gn = length(d.g);
  Curvature out;
  if (!(gn > kMinGradNorm)) return out;  // also catches NaN input
  const double inv_gn = 1.0 / gn;
  const Vec3d n = d.g * inv_gn;
  // Tangent basis: cross n with the axis least aligned with n (|n x e| >= sqrt(2/3)).
  const double ax = std::abs(n.x), ay = std::abs(n.y), az = std::abs(n.z);
  Vec3d b1;
  if (ax <= ay && ax <= az) {
    b1 = {0.0, n.z, -n.y};  // n x e_x
  } else if (ay <= az) {
    b1 = {-n.z, 0.0, n.x};  // n x e_y
  } else {
    b1 = {n.y, -n.x, 0.0};  // n x e_z
  }
  b1 = b1 * (1.0 / length(b1));
  const Vec3d b2 = cross(n, b1);
  const Vec3d hb1 = detail::hess_times(d, b1), hb2 = detail::hess_times(d, b2);
  const double a = dot(b1, hb1) * inv_gn;
  const double b = 0.5 * (dot(b1, hb2) + dot(b2, hb1)) * inv_gn;
  const double e = dot(b2, hb2) * inv_gn;
  const double mid = 0.5 * (a + e), half_diff = 0.5 * (a - e);
  const double disc = std::sqrt(half_diff * half_diff + b * b);
  out.grad_norm = gn;
  out.normal = n;
  out.mean = a + e;
  out.k1 = mid + disc;
  out.k2 = mid - disc;
  out.gauss = out.k1 * out.k2;
  return out;
}

// Mean and Gaussian curvature without the principal ones: H by the trace form and
// K = g^T adj(Hess) g / |g|^4 (Goldman 2005), adj the adjugate of the Hessian; both 0 when
// |grad u| <= kMinGradNorm. Equal to curvature_at's mean and gauss up to rounding, with one
// square root instead of three and no tangent basis.
struct MeanGauss {
  double mean = 0, gauss = 0;
};
inline MeanGauss mean_gauss_curvature_at(const float* v, const std::ptrdiff_t stride[3], double h) {
  const detail::Derivs d = detail::central_derivs(v, stride, h);
  const double g2 = dot(d.g, d.g);
  const double gn = std::sqrt(g2);
  if (!(gn > kMinGradNorm)) return {};
  const double trace = d.xx + d.yy + d.zz;
  const double ghg = dot(d.g, detail::hess_times(d, d.g));
  const double axx = d.yy * d.zz - d.yz * d.yz, ayy = d.xx * d.zz - d.xz * d.xz, azz = d.xx * d.yy - d.xy * d.xy;
  const double axy = d.xz * d.yz - d.xy * d.zz, axz = d.xy * d.yz - d.xz * d.yy, ayz = d.xy * d.xz - d.xx * d.yz;
  const Vec3d& g = d.g;
  const double gag = axx * g.x * g.x + ayy * g.y * g.y + azz * g.z * g.z +
                     2.0 * (axy * g.x * g.y + axz * g.x * g.z + ayz * g.y * g.z);
  return {(g2 * trace - ghg) / (g2 * gn), gag / (g2 * g2)};
}

// Mean curvature H = div(grad u / |grad u|) alone (trace form, no eigen-solve); 0 when
// |grad u| <= kMinGradNorm. Equals curvature_at(v, stride, h).mean up to rounding.
inline double mean_curvature_at(const float* v, const std::ptrdiff_t stride[3], double h) {
  const detail::Derivs d = detail::central_derivs(v, stride, h);
  const double g2 = dot(d.g, d.g);
  const double gn = std::sqrt(g2);
  if (!(gn > kMinGradNorm)) return 0.0;
  const double trace = d.xx + d.yy + d.zz;
  const double ghg = dot(d.g, detail::hess_times(d, d.g));
  return (g2 * trace - ghg) / (g2 * gn);
}

}  // namespace levelset::evolve
