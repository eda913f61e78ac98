// Upwind updates of |grad T| = 1 on a unit grid (h = 1), shared by the sweep and the march
// of redistance() (redistance.hpp).
//
// godunov(a, b, c): the first-order Godunov update (thesis 2.28 / 4.4) from the smaller
//   neighbour value along each axis.
// axis_term / solve_terms: the second-order variant; each axis contributes a term built from
//   its nearest upwind value m1 and the next one m2 on the same side, and solve_terms returns
//   the largest root over the axes that stay upwind.
// Inputs: unsigned distances in voxels, kInf = unknown (never upwind). Output: the updated
//   value, kInf when no axis has a finite value.
// Cost: branch-free O(1), no division, no libm errno path. Threading: pure functions.
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>

namespace levelset::detail {

// An unknown distance: a voxel not reached yet, or no neighbour on that side.
inline constexpr float kInf = std::numeric_limits<float>::infinity();

// sqrt(max(x, 0)); a NaN (inf - inf in a candidate that is not selected) gives 0 without the
// libm errno path.
inline float sqrt_nonneg(float x) { return std::sqrt(x > 0.0f ? x : 0.0f); }

// Godunov upwind update of |grad T| = 1 with h = 1 (thesis 2.28 / 4.4): the smallest root
// of sum_a max(T - m_a, 0)^2 = 1, where m_a is the smaller neighbour value along axis a.
// Only neighbours below the result take part; +inf neighbours never do. The one-, two- and
// three-axis candidates are all formed (relative to the smallest value, so large distances
// lose no precision) and the first one that stays upwind is selected.
inline float godunov(float a, float b, float c) {
  const float lo = std::min(a, b), hi = std::max(a, b);
  const float s0 = std::min(lo, c), mid = std::max(lo, c);
  const float s1 = std::min(hi, mid), s2 = std::max(hi, mid);
  const float p = s1 - s0, q = s2 - s0;
  const float t2 = 0.5f * (p + sqrt_nonneg(2.0f - p * p));
  const float pq = p + q;
  const float t3 = (pq + sqrt_nonneg(pq * pq - 3.0f * (p * p + q * q - 1.0f))) * (1.0f / 3.0f);
  const float t = 1.0f <= p ? 1.0f : (t2 <= q ? t2 : t3);
  return s0 < kInf ? s0 + t : kInf;
}

// Second-order upwind update: the largest root of sum_a alpha2_a (T - beta_a)^2 = 1 with
// the axes taken in increasing beta while they stay upwind (beta_a < T). A first-order axis
// has alpha2 = 1, beta = m1 (the smaller neighbour); a second-order axis, where the next
// value m2 along the same side continues monotonically (m2 <= m1), has the one-sided
// difference (3T - 4m1 + m2)/2: alpha2 = 9/4, beta = (4m1 - m2)/3. m2 is signed relative to
// the voxel, so a stencil may reach across the zero level to a fixed interface voxel.
inline constexpr float kAlpha2Second = 2.25f;

struct AxisTerm {
  float beta = kInf;
  float alpha2 = 1.0f;
};

inline AxisTerm axis_term(float m1, float m2, bool second_order) {
  const bool second = second_order && m2 <= m1;
  return {second ? (4.0f * m1 - m2) * (1.0f / 3.0f) : m1, second ? kAlpha2Second : 1.0f};
}

inline void order_terms(AxisTerm& x, AxisTerm& y) {
  const bool swap = y.beta < x.beta;
  const AxisTerm lo = swap ? y : x, hi = swap ? x : y;
  x = lo;
  y = hi;
}

// Like godunov(): candidates with one, two and three axes, relative to the smallest beta.
inline float solve_terms(AxisTerm t0, AxisTerm t1, AxisTerm t2) {
  order_terms(t0, t1);
  order_terms(t1, t2);
  order_terms(t0, t1);
  const float b0 = t0.beta, p = t1.beta - b0, q = t2.beta - b0;
  // 1/A from the number of second-order axes (a division would stall the chain).
  static constexpr float kInv2[3] = {1.0f / 2.0f, 1.0f / 3.25f, 1.0f / 4.5f};
  static constexpr float kInv3[4] = {1.0f / 3.0f, 1.0f / 4.25f, 1.0f / 5.5f, 1.0f / 6.75f};
  const int s0 = t0.alpha2 > 1.0f, s1 = t1.alpha2 > 1.0f, s2 = t2.alpha2 > 1.0f;
  const float T1 = s0 ? 2.0f / 3.0f : 1.0f;  // 1 / sqrt(alpha2)
  const float A2 = t0.alpha2 + t1.alpha2, B2 = t1.alpha2 * p, C2 = t1.alpha2 * p * p - 1.0f;
  const float T2 = (B2 + sqrt_nonneg(B2 * B2 - A2 * C2)) * kInv2[s0 + s1];
  const float A3 = A2 + t2.alpha2, B3 = B2 + t2.alpha2 * q, C3 = C2 + t2.alpha2 * q * q;
  const float T3 = (B3 + sqrt_nonneg(B3 * B3 - A3 * C3)) * kInv3[s0 + s1 + s2];
  const float T = T1 <= p ? T1 : (T2 <= q ? T2 : T3);
  return b0 < kInf ? b0 + T : kInf;
}

}  // namespace levelset::detail
