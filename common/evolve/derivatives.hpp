// Upwind first derivatives and numerical Hamiltonians for level-set evolution on a unit grid
// (h = 1: every result is in value units per voxel; divide by the voxel size outside).
//
// one_sided(v, stride, scheme): the one-sided derivatives D-u and D+u at the centre sample
//   v[0] of a line v[k * stride], k in [-kStencilReach, kStencilReach] (all must be readable
//   and finite; a dense tile with halo >= 3, grid/tile.hpp, gives the strides 1, dim, dim^2).
//   Schemes (Osher & Fedkiw, "Level Set Methods and Dynamic Implicit Surfaces", ch. 3):
//   - Upwind1: first-order differences, the thesis's Godunov upwind scheme (reach 1).
//   - Eno2: HJ-ENO of second order (O&F 3.3): the first difference plus the second-order
//     correction from the second difference of smaller magnitude (reach 2).
//   - Weno5: HJ-WENO of fifth order (Jiang & Peng 2000, SIAM J. Sci. Comput. 21; O&F 3.4,
//     eq. 3.25-3.35): three third-order ENO candidates, nonlinear weights from the standard
//     smoothness indicators, epsilon = 1e-6 * max(v_i^2) + 1e-99 over the five differences,
//     so the weights do not change when the data are scaled (reach 3).
// godunov_gradient_norm(d, beta): Godunov's upwind |grad u| for u_t + beta |grad u| = 0
//   (O&F ch. 6): beta > 0 sums max(max(D-,0)^2, min(D+,0)^2), beta < 0 sums
//   max(min(D-,0)^2, max(D+,0)^2) over the axes; beta == 0 returns 0 (no motion, so no upwind
//   direction: beta * |grad u| is 0 either way; use central_gradient_norm for a magnitude).
// upwind_advection(d, V): V . grad u with D- where V_a > 0, D+ where V_a < 0 (0 where V_a = 0),
//   V in voxels per unit time (O&F 3.1).
// llf_hamiltonian(d, beta, V, alpha): the Local Lax-Friedrichs numerical Hamiltonian
//   (Osher & Shu 1991; O&F 5.3.1) of H(p) = beta |p| + V . p:
//   H((p- + p+)/2) - sum_a alpha_a (p+_a - p-_a) / 2, alpha_a >= max |dH/dp_a| from the caller
//   (|beta| + |V_a| bounds it for this H; llf_alpha gives that bound).
// central_difference / central_gradient_norm: (v[s] - v[-s]) / 2 and the Euclidean norm of the
//   three, for parabolic (curvature) terms.
// Arithmetic: samples are float, everything inside is double.
// Cost: O(1) per call, no allocation, no libm beyond one sqrt (Godunov, LLF, central norm);
//   Weno5 is about 60 flops and 4 divisions per side. Threading: pure functions.
#pragma once

#include <string_view>

#include <algorithm>
#include <limits>
#include <cmath>
#include <cstddef>

namespace levelset::evolve {

enum class Scheme { Upwind1, Eno2, Weno5 };

// "godunov" (first-order upwind, the thesis's), "eno2", "weno5": the names the CLI and job
// files use. Error{InvalidArgument} for anything else.
Scheme scheme_from_name(std::string_view name);

// Samples needed on each side of the centre by the widest scheme (Weno5).
inline constexpr int kStencilReach = 3;
// Samples needed on each side by one scheme.
inline constexpr int stencil_reach(Scheme s) { return s == Scheme::Upwind1 ? 1 : s == Scheme::Eno2 ? 2 : 3; }

// D-u and D+u at the centre sample, value units per voxel.
struct OneSided {
  double minus = 0, plus = 0;
};

namespace detail {

// HJ-ENO2 one side (O&F 3.3): first difference d1 plus sign * c, c = the half second
// difference of smaller magnitude (the left one on a tie). a, b are the two half second
// differences, the one nearer the far side first.
inline double eno2_correction(double a, double b) { return std::abs(a) <= std::abs(b) ? a : b; }

// HJ-WENO5 from the five differences v1..v5 (O&F eq. 3.25-3.35); v3 is the difference across
// the upwind interval, v1 the farthest upwind. In three parts so that a loop over the first
// two has no branches and becomes vector code (upwind_batch): the candidates and the
// smoothness terms; their weighted sum as num / sum; the plain form where that sum under- or
// overflows (all-zero or extreme differences).
template <class R>
struct Weno5Parts {
  R phi1, phi2, phi3, e1, e2, e3;  // third-order candidates; smoothness indicators + epsilon
};

template <class R>
[[gnu::always_inline]] inline Weno5Parts<R> weno5_parts(R v1, R v2, R v3, R v4, R v5) {
  // Divisions by constants written as products (no -ffast-math here).
  constexpr R k3 = R(1) / R(3), k6 = R(1) / R(6), k1312 = R(13) / R(12);
  const R a1 = v1 - R(2) * v2 + v3, b1 = v1 - R(4) * v2 + R(3) * v3;
  const R a2 = v2 - R(2) * v3 + v4, b2 = v2 - v4;
  const R a3 = v3 - R(2) * v4 + v5, b3 = R(3) * v3 - R(4) * v4 + v5;
  const R vmax = std::max(std::max(std::max(v1 * v1, v2 * v2), std::max(v3 * v3, v4 * v4)), v5 * v5);
  // The tiny term keeps 0/0 away for all-zero differences; its square must not underflow.
  const R eps = R(1e-6) * vmax + (sizeof(R) == sizeof(double) ? R(1e-99) : R(1e-18));
  return {k3 * v1 - R(7) * k6 * v2 + R(11) * k6 * v3, -k6 * v2 + R(5) * k6 * v3 + k3 * v4,
          k3 * v3 + R(5) * k6 * v4 - k6 * v5,         k1312 * a1 * a1 + R(0.25) * b1 * b1 + eps,
          k1312 * a2 * a2 + R(0.25) * b2 * b2 + eps, k1312 * a3 * a3 + R(0.25) * b3 * b3 + eps};
}

// Weights d_k / e_k^2 times e1^2 e2^2 e3^2: the result is num / sum, one division instead of
// four, wherever weno5_sum_usable(sum).
template <class R>
[[gnu::always_inline]] inline void weno5_weighted(const Weno5Parts<R>& p, R& num, R& sum) {
  const R q1 = p.e2 * p.e3, q2 = p.e1 * p.e3, q3 = p.e1 * p.e2;
  const R W1 = R(0.1) * q1 * q1, W2 = R(0.6) * q2 * q2, W3 = R(0.3) * q3 * q3;
  sum = W1 + W2 + W3;
  num = W1 * p.phi1 + W2 * p.phi2 + W3 * p.phi3;
}

// Whether weno5_weighted's sum is normal and finite (false for NaN).
template <class R>
[[gnu::always_inline]] inline bool weno5_sum_usable(R sum) {
  return sum > std::numeric_limits<R>::min() && sum < std::numeric_limits<R>::max();
}

template <class R>
inline R weno5_plain(const Weno5Parts<R>& p) {
  const R w1 = R(0.1) / (p.e1 * p.e1), w2 = R(0.6) / (p.e2 * p.e2), w3 = R(0.3) / (p.e3 * p.e3);
  return (w1 * p.phi1 + w2 * p.phi2 + w3 * p.phi3) / (w1 + w2 + w3);
}

template <class R>
[[gnu::always_inline]] inline R weno5(R v1, R v2, R v3, R v4, R v5) {
  const Weno5Parts<R> p = weno5_parts(v1, v2, v3, v4, v5);
  R num, sum;
  weno5_weighted(p, num, sum);
  return weno5_sum_usable(sum) ? num / sum : weno5_plain(p);
}

// The scheme on any sample type (float in the API; double for tests that need exact data).
template <Scheme S, class T>
inline OneSided one_sided(const T* v, std::ptrdiff_t s) {
  const double u0 = double(v[0]);
  const double um1 = double(v[-s]), up1 = double(v[s]);
  if constexpr (S == Scheme::Upwind1) {
    return {u0 - um1, up1 - u0};
  } else if constexpr (S == Scheme::Eno2) {
    const double um2 = double(v[-2 * s]), up2 = double(v[2 * s]);
    const double cm1 = 0.5 * (um2 - 2.0 * um1 + u0);  // half second difference at i-1
    const double c0 = 0.5 * (um1 - 2.0 * u0 + up1);   // at i
    const double cp1 = 0.5 * (u0 - 2.0 * up1 + up2);  // at i+1
    return {(u0 - um1) + eno2_correction(cm1, c0), (up1 - u0) - eno2_correction(c0, cp1)};
  } else {
    const double um2 = double(v[-2 * s]), up2 = double(v[2 * s]);
    const double um3 = double(v[-3 * s]), up3 = double(v[3 * s]);
    const double d_m3 = um2 - um3, d_m2 = um1 - um2, d_m1 = u0 - um1;  // D+u at i-3, i-2, i-1
    const double d_0 = up1 - u0, d_p1 = up2 - up1, d_p2 = up3 - up2;   // D+u at i, i+1, i+2
    return {weno5<double>(d_m3, d_m2, d_m1, d_0, d_p1), weno5<double>(d_p2, d_p1, d_0, d_m1, d_m2)};
  }
}

template <class T>
inline OneSided one_sided_any(const T* v, std::ptrdiff_t stride, Scheme s) {
  switch (s) {
    case Scheme::Upwind1: return one_sided<Scheme::Upwind1>(v, stride);
    case Scheme::Eno2: return one_sided<Scheme::Eno2>(v, stride);
    case Scheme::Weno5: break;
  }
  return one_sided<Scheme::Weno5>(v, stride);
}

}  // namespace detail

// v points at the centre sample; v[k * stride] for k in [-stencil_reach(s), stencil_reach(s)]
// are read. Returns D-u and D+u in value units per voxel.
inline OneSided one_sided(const float* v, std::ptrdiff_t stride, Scheme s) {
  return detail::one_sided_any(v, stride, s);
}
// The same on double samples (reference computations, exact test data).
inline OneSided one_sided(const double* v, std::ptrdiff_t stride, Scheme s) {
  return detail::one_sided_any(v, stride, s);
}
// Compile-time scheme, for kernels instantiated per scheme.
template <Scheme S>
inline OneSided one_sided(const float* v, std::ptrdiff_t stride) {
  return detail::one_sided<S>(v, stride);
}

// All three axes at once: d[a] along stride[a] (x, y, z).
inline void one_sided_xyz(const float* v, const std::ptrdiff_t stride[3], Scheme s, OneSided d[3]) {
  for (int a = 0; a < 3; ++a) d[a] = one_sided(v, stride[a], s);
}

// One side only: D-u (minus = true) or D+u, for pure advection, which upwinds each axis by
// the sign of the velocity and never needs the other side (half the work of one_sided).
inline double one_side(const float* v, std::ptrdiff_t s, Scheme scheme, bool minus) {
  const double u0 = double(v[0]);
  const std::ptrdiff_t t = minus ? -s : s;  // towards the upwind side
  const double a1 = double(v[t]);
  const double first = minus ? u0 - a1 : a1 - u0;
  if (scheme == Scheme::Upwind1) return first;
  const double b1 = double(v[-t]), a2 = double(v[2 * t]);
  if (scheme == Scheme::Eno2) {
    // Same as one_sided's ENO2 side, mirrored for D+.
    const double far = 0.5 * (a2 - 2.0 * a1 + u0), mid = 0.5 * (a1 - 2.0 * u0 + b1);
    return minus ? first + detail::eno2_correction(far, mid) : first - detail::eno2_correction(mid, far);
  }
  const double b2 = double(v[-2 * t]), a3 = double(v[3 * t]);
  // Differences ordered from the far upwind side: for D- these are D+u at i-3 .. i+1.
  const double d1 = minus ? a2 - a3 : a3 - a2, d2 = minus ? a1 - a2 : a2 - a1, d3 = first;
  const double d4 = minus ? b1 - u0 : u0 - b1, d5 = minus ? b2 - b1 : b1 - b2;
  return detail::weno5<double>(d1, d2, d3, d4, d5);
}

// Godunov's upwind |grad u| for u_t + beta |grad u| = 0, value units per voxel; 0 for beta == 0.
inline double godunov_gradient_norm(const OneSided d[3], double beta) {
  double sum = 0.0;
  if (beta > 0.0) {
    for (int a = 0; a < 3; ++a) {
      const double m = std::max(d[a].minus, 0.0), p = std::min(d[a].plus, 0.0);
      sum += std::max(m * m, p * p);
    }
  } else if (beta < 0.0) {
    for (int a = 0; a < 3; ++a) {
      const double m = std::min(d[a].minus, 0.0), p = std::max(d[a].plus, 0.0);
      sum += std::max(m * m, p * p);
    }
  }
  return std::sqrt(sum);
}

// Upwind V . grad u for u_t + V . grad u = 0, V in voxels per unit time.
inline double upwind_advection(const OneSided d[3], const double velocity[3]) {
  double sum = 0.0;
  for (int a = 0; a < 3; ++a) {
    const double va = velocity[a];
    sum += va > 0.0 ? va * d[a].minus : va < 0.0 ? va * d[a].plus : 0.0;
  }
  return sum;
}

// alpha_a = |beta| + |V_a|: a valid LLF dissipation bound for H(p) = beta |p| + V . p
// (|dH/dp_a| = |beta p_a / |p| + V_a| <= |beta| + |V_a|).
inline void llf_alpha(double beta, const double velocity[3], double alpha[3]) {
  for (int a = 0; a < 3; ++a) alpha[a] = std::abs(beta) + std::abs(velocity[a]);
}

// Local Lax-Friedrichs numerical Hamiltonian of H(p) = beta |p| + V . p.
inline double llf_hamiltonian(const OneSided d[3], double beta, const double velocity[3], const double alpha[3]) {
  double p2 = 0.0, vp = 0.0, dissipation = 0.0;
  for (int a = 0; a < 3; ++a) {
    const double p = 0.5 * (d[a].minus + d[a].plus);
    p2 += p * p;
    vp += velocity[a] * p;
    dissipation += alpha[a] * 0.5 * (d[a].plus - d[a].minus);
  }
  return beta * std::sqrt(p2) + vp - dissipation;
}

// Central difference (v[stride] - v[-stride]) / 2, value units per voxel.
inline double central_difference(const float* v, std::ptrdiff_t stride) {
  return 0.5 * (double(v[stride]) - double(v[-stride]));
}
// |grad u| from the three central differences c[a] (value units per voxel).
inline double central_gradient_norm(const double c[3]) { return std::sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]); }
// The same from the samples around v along the three strides.
inline double central_gradient_norm(const float* v, const std::ptrdiff_t stride[3]) {
  const double c[3] = {central_difference(v, stride[0]), central_difference(v, stride[1]),
                       central_difference(v, stride[2])};
  return central_gradient_norm(c);
}

}  // namespace levelset::evolve
