#include "apps/height_quadric.hpp"

#include <algorithm>
#include <cmath>

namespace levelset::apps::detail {

namespace {

// Cholesky pivots below this fraction of the largest diagonal entry: the points do not span
// the quadric's six functions (e.g. all on a line across a thin part).
constexpr double kHeightConditioning = 1e-6;
// Each lane sums every kLanes-th point; the lanes are added pairwise at the end.
constexpr int kLanes = 4;
static_assert(kMaxNeighbors % kLanes == 0);

// Factorises the symmetric positive definite M (N x N, row-major) as L L^T in place (L in the
// lower triangle); false when a pivot falls below `relative` times the largest diagonal entry.
template <int N>
bool factor_spd(std::array<double, N * N>& M, double relative) {
  double scale = 0.0;
  for (int i = 0; i < N; ++i) scale = std::max(scale, M[std::size_t(i * N + i)]);
  if (!(scale > 0.0)) return false;
  for (int j = 0; j < N; ++j) {
    double d = M[std::size_t(j * N + j)];
    for (int q = 0; q < j; ++q) d -= M[std::size_t(j * N + q)] * M[std::size_t(j * N + q)];
    if (!(d > relative * scale)) return false;
    const double l = std::sqrt(d);
    M[std::size_t(j * N + j)] = l;
    for (int i = j + 1; i < N; ++i) {
      double v = M[std::size_t(i * N + j)];
      for (int q = 0; q < j; ++q) v -= M[std::size_t(i * N + q)] * M[std::size_t(j * N + q)];
      M[std::size_t(i * N + j)] = v / l;
    }
  }
  return true;
}

// Solves L L^T c = r in place for the factor of factor_spd, for R right-hand sides at once (the
// same operations on each as one at a time; the sides' division chains overlap).
template <int N, int R>
void solve_factored(const std::array<double, N * N>& L, std::array<std::array<double, N>, R>& rhs) {
  for (int i = 0; i < N; ++i) {  // L y = r
    for (auto& r : rhs) {
      double v = r[std::size_t(i)];
      for (int q = 0; q < i; ++q) v -= L[std::size_t(i * N + q)] * r[std::size_t(q)];
      r[std::size_t(i)] = v / L[std::size_t(i * N + i)];
    }
  }
  for (int i = N - 1; i >= 0; --i) {  // L^T c = y
    for (auto& r : rhs) {
      double v = r[std::size_t(i)];
      for (int q = i + 1; q < N; ++q) v -= L[std::size_t(q * N + i)] * r[std::size_t(q)];
      r[std::size_t(i)] = v / L[std::size_t(i * N + i)];
    }
  }
}

// The normal matrix sum w phi_a phi_b of the monomials phi = (1, u, v, u^2, uv, v^2) from its 15
// distinct entries, the moments sum w u^p v^q (p + q <= 4) by degree, then by decreasing p.
std::array<double, 36> normal_matrix(const std::array<double, 15>& moments) {
  static constexpr int kP[6] = {0, 1, 0, 2, 1, 0}, kQ[6] = {0, 0, 1, 0, 1, 2};
  auto index = [](int p, int q) {
    const int d = p + q;
    return d * (d + 1) / 2 + q;
  };
  std::array<double, 36> m{};
  for (int a = 0; a < 6; ++a)
    for (int b = 0; b < 6; ++b)
      m[std::size_t(a * 6 + b)] = moments[std::size_t(index(kP[a] + kP[b], kQ[a] + kQ[b]))];
  return m;
}

// The points scaled to (u, v) with their weights, in columns padded to whole lanes (weight 0).
struct Columns {
  alignas(64) double u[kMaxNeighbors], v[kMaxNeighbors], z[kMaxNeighbors], w[kMaxNeighbors];
  int padded = 0;
};

// Sums over the lanes of the weighted moments (mom), the squared-weight moments (mom2) and the
// right-hand side sum w z phi (r).
struct LaneSums {
  alignas(64) double mom[15][kLanes], mom2[15][kLanes], r[6][kLanes];
};

double lane_total(const double (&lanes)[kLanes]) {
  return (lanes[0] + lanes[1]) + (lanes[2] + lanes[3]);
}

// The per-point work, one lane per point: written so that the lanes become one vector (the
// sums local, so that no store through the result can alias the columns; mom2 always, as a
// branch in the loop would keep it scalar).
__attribute__((target_clones("avx2", "default"))) LaneSums accumulate(const Columns& c) {
  double mom[15][kLanes] = {}, mom2[15][kLanes] = {}, r[6][kLanes] = {};
  for (int i = 0; i < c.padded; i += kLanes) {
    for (int l = 0; l < kLanes; ++l) {
      const double u = c.u[i + l], v = c.v[i + l], w = c.w[i + l], ww = w * w;
      const double uu = u * u, uv = u * v, vv = v * v;
      const double m[15] = {1.0,    u,      v,       uu,      uv,      vv,      uu * u, uu * v,
                            u * vv, vv * v, uu * uu, uu * uv, uu * vv, uv * vv, vv * vv};
      for (int k = 0; k < 15; ++k) mom[k][l] += w * m[k];
      for (int k = 0; k < 15; ++k) mom2[k][l] += ww * m[k];
      const double wz = w * c.z[i + l];
      for (int k = 0; k < 6; ++k) r[k][l] += wz * m[k];
    }
  }
  LaneSums s;
  std::copy(&mom[0][0], &mom[0][0] + 15 * kLanes, &s.mom[0][0]);
  std::copy(&mom2[0][0], &mom2[0][0] + 15 * kLanes, &s.mom2[0][0]);
  std::copy(&r[0][0], &r[0][0] + 6 * kLanes, &s.r[0][0]);
  return s;
}

__attribute__((target_clones("avx2", "default"))) void weigh(Columns& c, int used) {
  for (int i = 0; i < c.padded; ++i)
    c.w[i] = (i < used ? 1.0 : 0.0) * exp_minus_unit(c.u[i] * c.u[i] + c.v[i] * c.v[i]);
}

// sum w and sum w e^2 of the residuals e = z - quadric(u, v).
__attribute__((target_clones("avx2", "default"))) std::array<double, 2> weighted_residual(
    const Columns& c, const std::array<double, 6>& q) {
  double ws[kLanes] = {}, rs[kLanes] = {};
  for (int i = 0; i < c.padded; i += kLanes)
    for (int l = 0; l < kLanes; ++l) {
      const double e = c.z[i + l] - quadric_at(q, c.u[i + l], c.v[i + l]);
      ws[l] += c.w[i + l];
      rs[l] += c.w[i + l] * e * e;
    }
  return {lane_total(ws), lane_total(rs)};
}

}  // namespace

HeightFit quadric_height(const TangentPoint* pts, int used, bool with_spread) {
  HeightFit f;
  if (used < 10) return f;
  used = std::min(used, kMaxNeighbors);
  double r2max = 0.0;
  for (int i = 0; i < used; ++i)
    r2max = std::max(r2max, pts[i].xi * pts[i].xi + pts[i].eta * pts[i].eta);
  if (!(r2max > 0.0)) return f;
  const double inv_r = 1.0 / std::sqrt(r2max);
  Columns c;
  c.padded = (used + kLanes - 1) / kLanes * kLanes;
  for (int i = 0; i < used; ++i) {
    c.u[i] = pts[i].xi * inv_r;
    c.v[i] = pts[i].eta * inv_r;
    c.z[i] = pts[i].z;
  }
  for (int i = used; i < c.padded; ++i) c.u[i] = c.v[i] = c.z[i] = 0.0;
  weigh(c, used);  // u^2 + v^2 <= 1 (to rounding) by the choice of R
  const LaneSums s = accumulate(c);
  std::array<double, 15> mom, mom2;
  std::array<double, 6> r;
  for (std::size_t k = 0; k < 15; ++k) {
    mom[k] = lane_total(s.mom[k]);
    mom2[k] = lane_total(s.mom2[k]);
  }
  for (std::size_t k = 0; k < 6; ++k) r[k] = lane_total(s.r[k]);
  std::array<double, 36> L = normal_matrix(mom);
  if (!factor_spd<6>(L, kHeightConditioning)) return f;
  // The coefficients, and y with M y = e0 for the spread: Var(c0) = y^T (sum w^2 phi phi^T) y.
  std::array<std::array<double, 6>, 2> rhs{r, {1.0, 0.0, 0.0, 0.0, 0.0, 0.0}};
  double var = 0.0;
  if (with_spread) {
    solve_factored<6, 2>(L, rhs);
    const std::array<double, 36> S = normal_matrix(mom2);
    const std::array<double, 6>& y = rhs[1];
    for (std::size_t a = 0; a < 6; ++a)
      for (std::size_t b = 0; b < 6; ++b) var += y[a] * S[a * 6 + b] * y[b];
  } else {
    std::array<std::array<double, 6>, 1> only{r};
    solve_factored<6, 1>(L, only);
    rhs[0] = only[0];
  }
  r = rhs[0];
  // The quadric's weighted residual: the points' noise, free of the surface's curvature
  // (which the quadric absorbs), corrected for the 6 fitted coefficients.
  const auto [wsum, rsum] = weighted_residual(c, r);
  f.residual = std::sqrt(rsum / (wsum * (1.0 - 6.0 / double(used))));
  // The surface crosses the normal line at x + z0 n; x's signed offset along the surface's
  // normal is -z0 cos(tilt), the slope (z_xi, z_eta) = (r1, r2) / R.
  const double slope2 = (r[1] * r[1] + r[2] * r[2]) * inv_r * inv_r;
  f.offset = -r[0] / std::sqrt(1.0 + slope2);
  f.spread = std::sqrt(std::max(0.0, var));
  f.c = r;
  f.inv_r = inv_r;
  f.ok = true;
  return f;
}

}  // namespace levelset::apps::detail
