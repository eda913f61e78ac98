// The sheet fits of point_distance.hpp: the k nearest points trimmed to the near sheet
// (one_sided_fit, sheet_plane), the height fits over them with their scale choice and noise
// correction (sheet_fit, sheet_model, SheetModel::at).
#include <algorithm>
#include <array>
#include <cmath>
#include <span>

#include "apps/height_quadric.hpp"
#include "apps/nearby_points.hpp"
#include "apps/point_distance.hpp"
#include "apps/point_fit_detail.hpp"

namespace levelset::apps {

using detail::HeightFit;
using detail::kMaxNeighbors;
using detail::Moments;
using detail::quadric_at;
using detail::quadric_height;
using detail::TangentPoint;

namespace {

// Height fits over at least 2 kSmallPatch points also fit the nearest 1 / kPatchRatio of
// them (at least kSmallPatch) and take that offset when the two differ by more than
// kPatchConfidence standard errors of the small fit (sheet_fit).
// Measured on bench_reconstruct --sweep's detailed meshes (armadillo, homer, man, dino at 50k
// points, 0.1 % noise: Chamfer -6 to -18 %; smooth ones within +-3 %); kappa 2 or 3 / ratio 3
// kept more of the large patches' bias, kappa 1 or 0 (always the small patch) lost the
// averaging on smooth shapes (bear +30 % at kappa 0). A cascade over several scales
// (Lepski's full rule) was no better than the two.
constexpr int kSmallPatch = 16;
constexpr int kPatchRatio = 2;
constexpr double kPatchConfidence = 1.5;
// The height fit's correction for the noise (correct_for_noise): c0 moves by this many times
// sigma^2 times the fitted patch's half mean curvature (points from the 3D ball; from the disc
// of HeightNoise::select), at most by kMaxNoiseCurvatureShift sigma.
constexpr double kNoiseBiasBall = 3.0;
constexpr double kNoiseBiasDisc = 2.0;
// The ball's factor for points chosen in the band about a first fit's quadric (kCurvedBandWeight):
// that fit's curvature is read nearer the truth's, so the same factor moved c0 0.3 units too
// far (test_sheet_fit_noise's torus: -0.75 units with 3.0, -0.33 with this; the sphere -0.48
// and -0.09). The disc's stays (the sphere +0.08, the torus -0.12 units).
constexpr double kNoiseBiasBallCurved = 2.4;
constexpr double kMaxNoiseCurvatureShift = 0.5;
// Selecting for noise, the height fit keeps the near sheet's points within at least this many
// noise sigmas (height_points). bench_reconstruct --sweep, 20k points, 0.5 % noise: 3 and 4
// alike on the whole (4 a little better on smooth shapes), 4 took in the far side of
// turbine.off's thin blades (Chamfer +21 %).
constexpr double kNoiseBand = 3.0;
// The soft scale choice's fit is made again over the points within the band about its
// largest patch's quadric where the choice keeps at least this weight on that patch (smooth:
// the quadric describes the patch, so its band holds the patch's rim, which the band about
// the plane cuts where the patch bends out of it). Below it the quadric may be the detail's
// biased fit, and a band about it would keep only the points that agree with it (the choice
// then reads no detail). bench_reconstruct --sweep, 0.1 % noise, seed 1, 20k points: median
// ratio 0.813 -> 0.794 (11 cases better by more than 1 %, 5 worse; bear_bis -2.4 %, retinal
// -3.9 %, knot1 +2.3 %); 50k: 0.702 -> 0.690 (4 better, 8 worse: knot1 +3.8 %, turbine
// +2.2 %, fandisk_large +2.0 %, cheese -4.3 %, retinal -4.1 %). The band about every fit's
// quadric (weight 0): 20k 0.752, but 13 worse (knot2 +11 %, bull, femur, triceratops +4 %).
constexpr double kCurvedBandWeight = 0.5;

}  // namespace

namespace {

// The k nearest points of x trimmed to the near sheet along n (see one_sided_fit), their
// first and second moments about x, and the trimming's outcome.
struct Sheet {
  // Only the first `count` entries are written (no zeroing: 5 KB per fit).
  std::array<std::uint32_t, kMaxNeighbors> idx;
  std::array<double, kMaxNeighbors> d2;
  std::array<double, kMaxNeighbors> t;  // (x - p_i).n
  int count = 0;
  double ref = 0.0;   // the near sheet's t
  double band = 0.0;  // kept: |t - ref| <= band
  double sigma = 0.0;
  int facing_away = 0;  // of the nearest points, left out as facing away (sheet_fit)
};

double median_of(std::array<double, 8> v, int size) {
  for (int i = 1; i < size; ++i)  // insertion sort of at most 8 values
    for (int j = i; j > 0 && v[std::size_t(j)] < v[std::size_t(j - 1)]; --j) std::swap(v[std::size_t(j)], v[std::size_t(j - 1)]);
  return size % 2 == 1 ? v[std::size_t(size / 2)] : 0.5 * (v[std::size_t(size / 2 - 1)] + v[std::size_t(size / 2)]);
}

// Drops the points facing away from n (see sheet_fit) from the first `count` of idx and d2,
// keeping their order; returns how many are left (all `count` when none would be).
int drop_facing_away(std::span<const Vec3f> facing, const Vec3d& n, int count, Sheet& s) {
  int kept = 0;
  for (int i = 0; i < count; ++i) {
    const Vec3f& f = facing[s.idx[std::size_t(i)]];
    if (double(f.x) * n.x + double(f.y) * n.y + double(f.z) * n.z < 0.0) continue;
    s.idx[std::size_t(kept)] = s.idx[std::size_t(i)];
    s.d2[std::size_t(kept++)] = s.d2[std::size_t(i)];
  }
  return kept > 0 ? kept : count;
}

// near: the same k nearest points from a prepared neighbourhood, or null (the tree).
// facing: empty, or one entry per point of the index (sheet_fit).
void find_sheet(const PointIndex& index, const NearbyPoints* nearby, const Vec3d& x, const Vec3d& n, int k,
                double min_band, std::span<const Vec3f> facing, Sheet& s) {
  k = std::clamp(k, 1, kMaxNeighbors);
  s.count = nearby ? nearby->k_nearest(x, k, s.idx.data(), s.d2.data()) : index.k_nearest(x, k, s.idx.data(), s.d2.data());
  if (s.count == 0) return;
  if (!facing.empty()) {
    const int all = s.count;
    s.count = drop_facing_away(facing, n, all, s);
    s.facing_away = all - s.count;
  }
  for (int i = 0; i < s.count; ++i) s.t[std::size_t(i)] = dot(x - index.points()[s.idx[std::size_t(i)]], n);
  const int m = std::min(s.count, 8);
  std::array<double, 8> near{};
  for (int i = 0; i < m; ++i) near[std::size_t(i)] = s.t[std::size_t(i)];
  s.ref = median_of(near, m);
  for (int i = 0; i < m; ++i) near[std::size_t(i)] = std::abs(near[std::size_t(i)] - s.ref);
  // 1.4826: the MAD of a normal sample; 1.25: the MAD of 8 values about their own median
  // is ~0.8 of the population's (measured on Gaussian samples of 8).
  s.sigma = 1.25 * 1.4826 * median_of(near, m);
  s.band = std::max(3.0 * s.sigma, min_band);
}

// The moments of the first `count` kept points of the sheet.
LocalFit sheet_moments(const PointIndex& index, const Vec3d& x, const Sheet& sh, int count) {
  if (sh.count == 0) return {};
  Moments m;
  for (int i = 0; i < std::min(count, sh.count); ++i) {
    if (std::abs(sh.t[std::size_t(i)] - sh.ref) > sh.band) continue;
    m.add(x - index.points()[sh.idx[std::size_t(i)]]);
  }
  LocalFit f = m.fit(std::sqrt(sh.d2[0]));
  f.spread = float(sh.sigma);
  return f;
}

}  // namespace

LocalFit one_sided_fit(const PointIndex& index, const Vec3d& x, const Vec3d& n, int k, double min_band) {
  Sheet sh;
  find_sheet(index, nullptr, x, n, k, min_band, {}, sh);
  return sheet_moments(index, x, sh, sh.count);
}

namespace {

// The height fit's points in the tangent frame (e1, e2, n) at x, nearest first: the first
// k_height of the sheet whose offset lies within the near sheet's band. Selecting for noise,
// that band is at least kNoiseBand sigma (the 8 nearest points' spread reads the noise ~15 %
// low and a flat slab cuts the sagitta's side of a curved patch's rim: both lift the rim and
// sink the fit, and the residual then under-reads the noise), and only the points inside the
// widest tangential disc whose slab the k_height ball holds whole are kept, at least half of
// the band's (past that disc the ball keeps a point by its height as well, again the rim's
// points nearest the tangent plane). With `about`, the band lies about that fit's quadric
// instead of the plane (kCurvedBandWeight). Returns how many were written.
int height_points(const PointIndex& index, const Vec3d& x, const Vec3d& n, const Vec3d& e1,
                  const Vec3d& e2, const Sheet& sh, int k_height, const HeightNoise& noise,
                  std::array<TangentPoint, kMaxNeighbors>& pts, const HeightFit* about = nullptr) {
  const int count = std::min(k_height, sh.count);
  const bool select = noise.select && noise.sigma > 0.0 && count > 0;
  const double band = select ? std::max(sh.band, kNoiseBand * noise.sigma) : sh.band;
  int used = 0;
  for (int i = 0; i < count; ++i) {
    const Vec3d v = index.points()[sh.idx[std::size_t(i)]] - x;
    const TangentPoint p{dot(v, e1), dot(v, e2), dot(v, n)};
    if (about) {
      const double zq = quadric_at(about->c, p.xi * about->inv_r, p.eta * about->inv_r);
      if (std::abs(p.z - zq) > band) continue;
    } else if (std::abs(sh.t[std::size_t(i)] - sh.ref) > band) {
      continue;
    }
    pts[std::size_t(used++)] = p;
  }
  if (!select || used < 2) return used;
  // The disc, widened where it would keep fewer than half the band's points; the ball's order
  // kept (the scale choice's smaller patch is the nearer half of it).
  std::array<double, kMaxNeighbors> radius2, sorted;
  for (int i = 0; i < used; ++i) {
    const TangentPoint& p = pts[std::size_t(i)];
    radius2[std::size_t(i)] = sorted[std::size_t(i)] = p.xi * p.xi + p.eta * p.eta;
  }
  const double reach = std::abs(sh.ref) + band;
  double disc2 = sh.d2[std::size_t(count - 1)] - reach * reach;
  const auto half = sorted.begin() + (used - 1) / 2;
  std::nth_element(sorted.begin(), half, sorted.begin() + used);
  disc2 = std::max(disc2, *half);
  int kept = 0;
  for (int i = 0; i < used; ++i)
    if (radius2[std::size_t(i)] <= disc2) pts[std::size_t(kept++)] = pts[std::size_t(i)];
  return kept;
}

// A height fit with the variance of its offset (world^2).
struct ScaledFit {
  HeightFit fit;
  double variance = 0.0;
  double large_weight = 1.0;  // the weight of the largest patch's fit in `fit`
};

ScaledFit with_variance(const HeightFit& f) {
  const double se = f.residual * f.spread;
  return {f, se * se, 1.0};
}

// The estimate `large` shrunk toward `smaller` (a fit over the nearer part of the same points):
// for nested least-squares fits Var(smaller - large) ~ v_small - v_large, so the large fit's
// bias^2 reads D^2 - (v_small - v_large) with D the offsets' difference, and the weight of
// `large` that minimises the blend's mean squared error is (v_small - v_large) / D^2 where
// D^2 exceeds that variance, else 1. The quadrics are blended coefficient by coefficient.
ScaledFit blend_scales(const ScaledFit& large, const ScaledFit& smaller) {
  const HeightFit &a = large.fit, &b = smaller.fit;
  const double dv = std::max(0.0, smaller.variance - large.variance), d = a.offset - b.offset;
  const double w = d * d <= dv ? 1.0 : dv / (d * d);
  ScaledFit out = large;
  out.large_weight = w * large.large_weight;
  // Coefficient i is in units of inv_r^degree (c0: world; c1, c2: degree 1; c3..c5: degree 2):
  // the smaller fit's, in the large one's units, are scaled by (inv_r_small / inv_r_large)^degree.
  const double q = b.inv_r / a.inv_r;
  const double scale[6] = {1.0, q, q, q * q, q * q, q * q};
  for (std::size_t i = 0; i < 6; ++i) out.fit.c[i] = w * a.c[i] + (1.0 - w) * b.c[i] * scale[i];
  out.fit.offset = w * a.offset + (1.0 - w) * b.offset;
  out.fit.residual = w * a.residual + (1.0 - w) * b.residual;
  // Var(w L + (1 - w) S) with Cov(L, S) ~ Var(L) for nested fits.
  out.variance = w * w * large.variance + (1.0 - w) * (1.0 - w) * smaller.variance +
                 2.0 * w * (1.0 - w) * large.variance;
  return out;
}

// The soft three-scale choice (HeightNoise::soft): the fit over all `used` points blended
// toward the fit over the nearer half, that toward the fit over the nearer quarter
// (blend_scales), each scale at least kSmallPatch points. `large` is the fit over all of them
// with its spread (returned where the smaller scales do not fit).
ScaledFit soft_scale_choice(const TangentPoint* pts, int used, const HeightFit& large) {
  const int half = std::max(kSmallPatch, used / 2), quarter = std::max(kSmallPatch, used / 4);
  if (used < 2 * half) return {large, 0.0, 1.0};
  const HeightFit medium = quadric_height(pts, half, true);
  if (!medium.ok) return {large, 0.0, 1.0};
  ScaledFit out = blend_scales(with_variance(large), with_variance(medium));
  if (half >= 2 * quarter) {
    const HeightFit small = quadric_height(pts, quarter, true);
    if (small.ok) out = blend_scales(out, with_variance(small));
  }
  return out;
}

// The quadric's coefficient of curvature c3 + c5 over R^2 (world^-1: half the mean curvature
// k1 + k2, signed along n: negative where the surface bends away from n).
double half_mean_curvature(const HeightFit& f) { return (f.c[3] + f.c[5]) * f.inv_r * f.inv_r; }

// Noise in the points biases a regressed height toward a curved patch's concave side, in
// units of kappa sigma^2 (kappa = half_mean_curvature of the fit):
// - 1 unit from the errors in the tangential coordinates: a point seen at (xi, eta) was sampled
//   about N((xi, eta), sigma^2) on the surface, so the heights regressed there are the
//   surface's plus sigma^2 / 2 times its Laplacian 2 kappa;
// - about 1 more from the choice of the points: the 3D ball of the nearest keeps those of its
//   rim that the noise moved toward the tangent plane (the rim lifted, the fit sunk, and its
//   curvature read ~0.7 of the truth's); the tangential disc of HeightNoise::select keeps
//   fewer of them.
// The factors are what leaves fits at points of a noisy sphere and torus unbiased
// (tests/unit/test_sheet_fit_noise.cpp: 2.0 units measured uncorrected; 1.2-1.3 left by the
// tangential unit alone, the correction before): kNoiseBiasBall for the ball's fits,
// kNoiseBiasDisc for the disc's. In the reconstruction (256-point fits at the final level,
// sigma 0.37 voxel) spheres of radius 7 voxels came out 0.0375 voxel small on average with the
// tangential unit alone, 0.004 voxel large with these factors (and snap_level's restart); a
// torus of tube radius 6 voxels 0.027 voxel small and 0.0001 large. c0
// moves by at most kMaxNoiseCurvatureShift sigma, where the quadric bends on the noise's own
// scale and the expansion no longer holds. kappa is the adopted fit's (after the scale
// choice). Measured against it (200k points, 0.1 % noise, truth-to-surface mean distance): the
// largest patch's kappa, bear 3 % better and armadillo 4 % worse; each scale corrected with its
// own (the smaller patches' kappa is noisier, and multiplied here), bear 4 % worse and
// armadillo 1 % better.
void correct_for_noise(HeightFit& f, double kappa, double sigma, double factor) {
  if (!(sigma > 0.0)) return;
  const double shift = factor * kappa * sigma * sigma;
  f.c[0] -= std::clamp(shift, -kMaxNoiseCurvatureShift * sigma, kMaxNoiseCurvatureShift * sigma);
  const double slope2 = (f.c[1] * f.c[1] + f.c[2] * f.c[2]) * f.inv_r * f.inv_r;
  f.offset = -f.c[0] / std::sqrt(1.0 + slope2);
}

SheetModel sheet_model_from(const PointIndex& index, const NearbyPoints* near, const Vec3d& x, const Vec3d& n, int k,
                            int k_height, double min_band, const HeightNoise& noise, std::span<const Vec3f> facing) {
  Sheet sh;
  find_sheet(index, near, x, n, std::max(k, k_height), min_band, facing, sh);
  SheetModel f;
  f.x = x;
  f.n = n;
  f.plane = sheet_moments(index, x, sh, k);
  f.facing_away = sh.facing_away;
  // Height function z(xi, eta) over the tangent plane of n at x.
  const Vec3d t1 = std::abs(n.x) < 0.6 ? cross(n, Vec3d{1, 0, 0}) : cross(n, Vec3d{0, 1, 0});
  const Vec3d e1 = t1 / length(t1);
  const Vec3d e2 = cross(n, e1);
  f.e1 = e1;
  f.e2 = e2;
  std::array<TangentPoint, kMaxNeighbors> pts;  // the first `used` entries are written
  const int used = height_points(index, x, n, e1, e2, sh, k_height, noise, pts);
  HeightFit fit = quadric_height(pts.data(), used, noise.soft);
  if (!fit.ok) return f;
  // The patch's scale from the data (intersection of confidence intervals, Lepski): the
  // large patch averages the noise, but where the surface bends more than a quadric
  // describes over it (fine detail), its offset leaves the small patch's confidence
  // interval: then the small patch's (unbiased) offset is taken.
  const int small = std::max(kSmallPatch, used / kPatchRatio);
  bool curved = false;
  if (noise.soft) {
    ScaledFit chosen = soft_scale_choice(pts.data(), used, fit);
    if (chosen.large_weight >= kCurvedBandWeight) {
      // A smooth patch: its points chosen again in the band about the large fit's quadric
      // (the plane's band cuts a curved patch's rim) and the choice made again over them.
      const int again = height_points(index, x, n, e1, e2, sh, k_height, noise, pts, &fit);
      const HeightFit refit = quadric_height(pts.data(), again, true);
      if (refit.ok) {
        chosen = soft_scale_choice(pts.data(), again, refit);
        curved = true;
      }
    }
    fit = chosen.fit;
    f.large_weight = chosen.large_weight;
  } else if (used >= 2 * small) {
    const HeightFit small_fit = quadric_height(pts.data(), small, true);
    if (small_fit.ok && std::abs(fit.offset - small_fit.offset) > kPatchConfidence * small_fit.residual * small_fit.spread) {
      fit = small_fit;
      f.large_weight = 0.0;
    }
  }
  const double kappa = half_mean_curvature(fit);
  const double factor = noise.select ? kNoiseBiasDisc
                        : curved     ? kNoiseBiasBallCurved
                                     : kNoiseBiasBall;
  correct_for_noise(fit, kappa, noise.sigma, factor);
  f.c = fit.c;
  f.inv_r = fit.inv_r;
  f.noise_curvature = noise.sigma > 0.0 ? factor * kappa : 0.0;
  f.height_residual = fit.residual;
  f.has_height = true;
  return f;
}

}  // namespace

SheetFit SheetModel::at(const Vec3d& y) const {
  SheetFit f;
  f.plane = plane;
  f.facing_away = facing_away;
  const Vec3d d = y - x;
  if (d.x != 0.0 || d.y != 0.0 || d.z != 0.0) {
    // Moments about y: mean(y - p) = a + d; mean (y - p)(y - p)^T = S + d a^T + a d^T + d d^T.
    const double ax = plane.ax, ay = plane.ay, az = plane.az;
    f.plane.ax = float(ax + d.x);
    f.plane.ay = float(ay + d.y);
    f.plane.az = float(az + d.z);
    f.plane.sxx = float(double(plane.sxx) + 2.0 * d.x * ax + d.x * d.x);
    f.plane.sxy = float(double(plane.sxy) + d.x * ay + ax * d.y + d.x * d.y);
    f.plane.sxz = float(double(plane.sxz) + d.x * az + ax * d.z + d.x * d.z);
    f.plane.syy = float(double(plane.syy) + 2.0 * d.y * ay + d.y * d.y);
    f.plane.syz = float(double(plane.syz) + d.y * az + ay * d.z + d.y * d.z);
    f.plane.szz = float(double(plane.szz) + 2.0 * d.z * az + d.z * d.z);
  }
  if (!has_height) return f;
  // y's foot on the tangent plane (u, v) and its height zeta over x; the quadric relative to
  // y is z - zeta, so y's offset is -(z(u, v) - zeta) times the cosine of the slope there.
  const double u = dot(d, e1) * inv_r, v = dot(d, e2) * inv_r, zeta = dot(d, n);
  const double z = quadric_at(c, u, v);
  const double zu = c[1] + 2.0 * c[3] * u + c[4] * v, zv = c[2] + c[4] * u + 2.0 * c[5] * v;
  const double slope2 = (zu * zu + zv * zv) * inv_r * inv_r;
  f.height_offset = -(z - zeta) / std::sqrt(1.0 + slope2);
  f.noise_gain = noise_curvature / std::sqrt(1.0 + slope2);
  f.height_residual = height_residual;
  f.has_height = true;
  f.large_weight = large_weight;
  return f;
}

SheetFit sheet_fit(const PointIndex& index, const Vec3d& x, const Vec3d& n, int k, int k_height, double min_band,
                   HeightNoise noise) {
  return sheet_model_from(index, nullptr, x, n, k, k_height, min_band, noise, {}).at(x);
}

SheetFit sheet_fit(const NearbyPoints& near, const Vec3d& x, const Vec3d& n, int k, int k_height, double min_band,
                   HeightNoise noise, std::span<const Vec3f> facing) {
  return sheet_model_from(near.index(), &near, x, n, k, k_height, min_band, noise, facing).at(x);
}

SheetModel sheet_model(const NearbyPoints& near, const Vec3d& x, const Vec3d& n, int k, int k_height,
                       double min_band, HeightNoise noise, std::span<const Vec3f> facing) {
  return sheet_model_from(near.index(), &near, x, n, k, k_height, min_band, noise, facing);
}

LocalFit sheet_plane(const NearbyPoints& near, const Vec3d& x, const Vec3d& n, int k, double min_band,
                     std::span<const Vec3f> facing) {
  Sheet sh;
  find_sheet(near.index(), &near, x, n, k, min_band, facing, sh);
  return sheet_moments(near.index(), x, sh, k);
}

}  // namespace levelset::apps
