// The height fit of the sheet fits (sheet_fit.cpp): a weighted least-squares quadric over points
// given in a tangent frame at x.
//
// Contract: quadric_height(pts, used, with_spread) fits z = c0 + c1 u + c2 v + c3 u^2 + c4 uv +
//   c5 v^2 to the first `used` points (at most kMaxNeighbors), (u, v) = (xi, eta) / R with R the
//   largest tangential radius among them, weights exp(-(u^2 + v^2)). ok is false for fewer
//   than 10 points, for points all on the normal line, and where the points do not span the six
//   monomials (a Cholesky pivot below 1e-6 of the largest diagonal entry: e.g. all on a line).
//   offset: x's signed distance to the quadric along its normal at the crossing (world units,
//   -c0 cos(tilt)); residual: the weighted RMS residual corrected for the 6 coefficients
//   (world); spread (with_spread only, else 0): the standard error of c0 per unit noise; c and
//   inv_r = 1 / R as above.
// Cost: O(used): ~9 ns a point where the CPU has AVX2, ~25 without, plus ~0.5 us for the 6x6
//   factorisation (one, shared by the coefficients and the spread).
// Threading: a pure function. The sums run in kLanes fixed lanes added in a fixed order, so every
//   instruction set it is built for (target_clones) gives the same result bit for bit.
#pragma once

#include <array>

#include "apps/point_fit_detail.hpp"

namespace levelset::apps::detail {

// A point in the tangent frame of a fit: tangential (xi, eta), height z along the normal.
struct TangentPoint {
  double xi, eta, z;
};

struct HeightFit {
  bool ok = false;
  double offset = 0.0;
  double residual = 0.0;
  double spread = 0.0;
  std::array<double, 6> c{};  // the quadric over (u, v) = (xi, eta) * inv_r
  double inv_r = 0.0;
};

HeightFit quadric_height(const TangentPoint* pts, int used, bool with_spread);

// The quadric z = c0 + c1 u + c2 v + c3 u^2 + c4 uv + c5 v^2 at (u, v).
inline double quadric_at(const std::array<double, 6>& c, double u, double v) {
  return c[0] + c[1] * u + c[2] * v + c[3] * u * u + c[4] * u * v + c[5] * v * v;
}

// exp(-s) for s in [0, 1] (a little beyond, to rounding): e^(-1/2) exp(1/2 - s) by its Taylor
// polynomial of degree 14, within 4e-16 relative of std::exp there (the remainder
// 0.5^15 / 15! e^0.5 is 4e-17). A polynomial, so the fit's weights vectorise.
inline double exp_minus_unit(double s) {
  const double t = 0.5 - s;
  constexpr double kInverseFactorial[15] = {1.0,
                                            1.0,
                                            1.0 / 2.0,
                                            1.0 / 6.0,
                                            1.0 / 24.0,
                                            1.0 / 120.0,
                                            1.0 / 720.0,
                                            1.0 / 5040.0,
                                            1.0 / 40320.0,
                                            1.0 / 362880.0,
                                            1.0 / 3628800.0,
                                            1.0 / 39916800.0,
                                            1.0 / 479001600.0,
                                            1.0 / 6227020800.0,
                                            1.0 / 87178291200.0};
  double p = kInverseFactorial[14];
  for (int n = 13; n >= 0; --n) p = p * t + kInverseFactorial[n];
  return p * 0.60653065971263342360;  // e^(-1/2)
}

}  // namespace levelset::apps::detail
