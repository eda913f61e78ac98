// Distance to an unorganised point set: a kd-tree (nanoflann) over the points, the exact
// unsigned distance d(x) with its direction, and per-voxel local surface fits.
//
// PointIndex: builds the kd-tree once (serial, O(N log N)); its queries are const and safe to
//   run concurrently. Points are copied; indices refer to the input order. Ties between
//   equidistant points are broken by the tree, identically for every thread count.
// point_distance: for each query position x, d(x) = min_i |x - p_i| (exact, double) and the
//   unit direction (x - p*) / d of the gradient of d (zero where d = 0). TBB over queries.
// LocalFit (per voxel centre x, from the k nearest points p_i):
//   d      distance to the nearest point;
//   a      x - c, c the centroid of the k points;
//   s      the second moments S = mean (x - p_i)(x - p_i)^T (xx, xy, xz, yy, yz, zz).
//   With a unit normal n and the mean curvature H (= k1 + k2) of a surface through x,
//   signed_offset(n, H) = a.n - (H / 4) (tr S - n^T S n) estimates the signed distance of x
//   to the surface the points sample: the mean offset of x from the points along n, minus
//   the mean amount mean(rho_i^2) H / 4 by which points at tangential distance rho_i lie
//   below a tangent plane of a surface with that mean curvature (exact to second order for
//   isotropic neighbourhoods). Averaging over k points divides the noise by sqrt(k); with
//   k = 1 it is the distance to the nearest point's tangent plane.
// point_fit_field: the LocalFit of every active voxel of `where` (a NarrowBand used as the
//   set of voxels), in the band's value order; O(voxels * k log N), TBB over bricks,
//   identical for any thread count. Progress per brick batch, cancellable.
// sample_gap: the q-quantile over up to `samples` points (every (N / samples)-th, so the result
//   is deterministic) of the distance from a point to its k-th nearest other point: the
//   radius of the holes a sampling leaves, e.g. what an offset surface of the points must
//   close. O(samples * k log N), serial.
// Units: world. Errors: Error{InvalidArgument} for an empty point set, k < 1 or k > 256;
//   Error{NonFinite} for a non-finite point; Error{Cancelled} through the hook.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <memory>
#include <span>
#include <utility>
#include <vector>

#include "core/progress.hpp"
#include "core/vec3.hpp"
#include "grid/narrow_band.hpp"

namespace levelset::apps {

class PointIndex {
 public:
  explicit PointIndex(std::span<const Vec3d> points);
  ~PointIndex();
  PointIndex(const PointIndex&) = delete;
  PointIndex& operator=(const PointIndex&) = delete;

  std::size_t size() const { return points_.size(); }
  const std::vector<Vec3d>& points() const { return points_; }

  struct Nearest {
    std::uint32_t index = 0;
    double distance = 0.0;
  };
  Nearest nearest(const Vec3d& x) const;
  // Up to k nearest points, closest first; returns how many were written (min(k, size)).
  int k_nearest(const Vec3d& x, int k, std::uint32_t* indices, double* distances_squared) const;
  // All points within `radius` of x (index, squared distance), unordered; `out` is cleared.
  void within(const Vec3d& x, double radius, std::vector<std::pair<std::uint32_t, double>>& out) const;
  // The same, stopping after `cap` points: false (and `out` incomplete) when there are more.
  bool within(const Vec3d& x, double radius, std::size_t cap, std::vector<std::pair<std::uint32_t, double>>& out) const;

 private:
  struct Tree;
  std::vector<Vec3d> points_;
  std::unique_ptr<Tree> tree_;
};

double sample_gap(const PointIndex& index, int k, double quantile, std::size_t samples);

struct PointDistanceOptions {
  ProgressHook progress;
};

struct PointDistanceResult {
  std::vector<double> distance;  // one per query
  std::vector<Vec3d> direction;  // (x - closest point) / distance, or zero
  std::vector<std::uint32_t> closest;  // index of the closest point
  double seconds = 0.0;
};

PointDistanceResult point_distance(const PointIndex& index, std::span<const Vec3d> queries,
                                   const PointDistanceOptions& options = {});

struct LocalFit {
  float d = 0.0f;
  float ax = 0.0f, ay = 0.0f, az = 0.0f;
  float sxx = 0.0f, sxy = 0.0f, sxz = 0.0f, syy = 0.0f, syz = 0.0f, szz = 0.0f;
  float spread = 0.0f;  // one_sided_fit only: the robust sigma of the nearest points' offsets

  // max_correction bounds the curvature term (a neighbourhood that wraps around a thin
  // part is no local patch; the correction is meant for ~0.1 voxel).
  double signed_offset(const Vec3d& n, double mean_curvature, double max_correction) const {
    const double an = double(ax) * n.x + double(ay) * n.y + double(az) * n.z;
    const double nsn = double(sxx) * n.x * n.x + double(syy) * n.y * n.y + double(szz) * n.z * n.z +
                       2.0 * (double(sxy) * n.x * n.y + double(sxz) * n.x * n.z + double(syz) * n.y * n.z);
    const double tangential = std::max(0.0, double(sxx) + double(syy) + double(szz) - nsn);
    return an - std::clamp(0.25 * mean_curvature * tangential, -max_correction, max_correction);
  }
};

// The fit at one position (k nearest points of the index). Thread-safe.
LocalFit local_fit(const PointIndex& index, const Vec3d& x, int k);

// The fit at x of the k nearest points lying on the same sheet as the nearest ones, seen
// along the unit normal n: t_i = (x - p_i).n; t_ref, the median t of the min(k, 8) nearest,
// and their robust spread sigma = 1.25 * 1.4826 median |t_i - t_ref| (LocalFit::spread: a local
// noise estimate); the points with
// |t_i - t_ref| <= max(3 sigma, min_band) make the fit (symmetric trimming: no bias for
// symmetric noise). Where a part of the surface is thinner than the neighbourhood, its far
// sheet (t larger by the thickness) drops out, so the fit is no longer pulled to the part's
// middle plane (which flattened thin parts, e.g. the bunny's ears, into sheets whose
// marching-cubes topology followed the noise). Thread-safe.
LocalFit one_sided_fit(const PointIndex& index, const Vec3d& x, const Vec3d& n, int k, double min_band);

// How the height fit treats the points' noise (sheet_fit). sigma (world, per axis, isotropic; 0:
// none assumed): a curved patch's regressed height lies toward its concave side by about
// 2 kappa sigma^2 (kappa the half mean curvature: one kappa sigma^2 through the noise in the
// tangential coordinates, about one more through the choice of the nearest points, whose rim
// keeps the points the noise moved toward the tangent plane); c0 is corrected by a multiple of
// the fitted kappa sigma^2 (sheet_fit.cpp correct_for_noise), at most by sigma / 2. select: the
// height fit's points are chosen without a bias toward the tangent plane: the band is at least
// 3 sigma, and the points lie in a tangential disc the k_height ball holds whole (a ball cuts the
// slab's corners, so it keeps a curved patch's rim points by their height). The scale choice's
// smaller patch stays the 3D-nearest half (a disc there measured 1-2 % worse on smooth shapes
// at 0.5 % noise, bench_reconstruct --sweep). The disc keeps at least half the band's points
// (where the ball is barely wider than the slab, a smaller disc would leave the fit too few);
// it costs a quarter of them under 0.5 % noise, which pays only where the noise is strong.
// soft: the patch's scale by the soft three-scale choice instead of the two-scale rule (see
// sheet_fit), for a k_height that is a multiple of what the two-scale rule would take.
struct HeightNoise {
  double sigma = 0.0;   // world
  bool select = false;  // points chosen without a bias toward the tangent plane
  bool soft = false;    // the patch's scale by the soft three-scale choice (sheet_fit)
};

// The one-sided fit of the first k points and a second-order fit of the first k_height
// (both trimmed to the near sheet as one_sided_fit; the height fit as `noise` says): in the
// frame of the unit normal n at x,
// the height z = c0 + c1 xi + c2 eta + c3 xi^2 + c4 xi eta + c5 eta^2 of the points above the
// tangent plane, by least squares weighted exp(-rho^2 / R^2) (rho the tangential distance
// from x, R the largest among the kept points). height_offset = -c0 / sqrt(1 + |grad z|^2)
// is x's signed distance to that quadric: no bias from the surface's curvature (the plane /
// centroid fit's O(rho^2 H)) and no dependence on where the points lie around x, so it
// needs no curvature correction; height_residual, the weighted RMS of the points' heights
// about the quadric (times sqrt(n / (n - 6)); before the noise correction of c0), estimates the
// noise without the curvature's sagitta that the plane fit's spread carries. The patch's scale
// follows the data: with at least 32 kept points a second quadric over the nearest half is
// fitted, and its offset taken where the two differ by more than 1.5 of its standard errors
// (the large patch bent by detail the quadric cannot follow; intersection of confidence
// intervals, Lepski). With noise.soft, the fits over all, the nearest half and the nearest
// quarter (each at least 16 points) are blended instead: each larger one shrunk toward the
// next smaller by the weight that minimises the mean squared error given the bias^2 their
// offsets' difference reveals beyond its noise (for nested fits Var(small - large) ~
// v_small - v_large: weight min(1, (v_small - v_large) / D^2)); smooth patches keep the large
// fit's averaging, detail falls back toward the small fits without a hard threshold's
// undetected bias (tests/unit/test_sheet_fit_scales.cpp); where the choice keeps at least half
// the weight on the largest patch, the points are chosen again in the band about its quadric
// (not the plane's, which cuts a curved patch's rim) and the choice is made again. has_height is
// false (height_offset 0) with fewer than 10 kept points or an ill-conditioned system. Thread-safe.
struct SheetFit {
  LocalFit plane;
  double height_offset = 0.0;
  double height_residual = 0.0;  // the quadric's weighted RMS residual (world): a noise estimate
  // d height_offset / d sigma^2 of the noise correction (1 / world): the offset for another
  // sigma is height_offset + noise_gain (sigma'^2 - sigma^2), within the correction's bound.
  double noise_gain = 0.0;
  // SheetModel::large_weight of the model it came from (1 without a height fit).
  double large_weight = 1.0;
  int facing_away = 0;  // of the nearest points, left out as facing away (facing)
  bool has_height = false;
};
SheetFit sheet_fit(const PointIndex& index, const Vec3d& x, const Vec3d& n, int k, int k_height, double min_band,
                   HeightNoise noise = {});
// The same, its k nearest points from a neighbourhood prepared around x (apps/nearby_points.hpp).
// facing (optional, one entry per point of the index, or empty): which way each point's side
// of a surface estimate faces, a unit vector (zero: not known). Of the k nearest points, those
// facing away from n (facing . n < 0) are left out before the sheet is sought, unless that
// leaves none: the far side of a part thinner than the neighbourhood and the other wall of a
// narrow gap, whose points the band about the near sheet takes in under noise of a third of
// the part's thickness or more (the fit then sinks toward the part's middle).
class NearbyPoints;
SheetFit sheet_fit(const NearbyPoints& near, const Vec3d& x, const Vec3d& n, int k, int k_height, double min_band,
                   HeightNoise noise = {}, std::span<const Vec3f> facing = {});

// A sheet fit made once at x and evaluated at positions y near it (the voxels of a small block
// can share one fit). at(y): the plane fit's moments moved to y (a and S are moments about the
// evaluation point, moved exactly; LocalFit::d stays x's) and y's signed distance to the
// fitted quadric (-(z(u, v) - zeta) / sqrt(1 + |grad z|^2) at y's foot (u, v) on the tangent
// plane, zeta its height over x); at(x) equals sheet_fit at x bit for bit. The evaluation is
// as good as the quadric is away from the patch's centre: keep |y - x| well inside
// patch_radius().
struct SheetModel {
  Vec3d x{}, n{}, e1{}, e2{};
  LocalFit plane;
  bool has_height = false;
  std::array<double, 6> c{};  // z = c0 + c1 u + c2 v + c3 u^2 + c4 u v + c5 v^2, (u, v) = (xi, eta) * inv_r
  double inv_r = 0.0;
  double noise_curvature = 0.0;  // the noise correction's c0 shift per sigma^2 (world^-1; 0 without noise)
  double height_residual = 0.0;
  // The weight of the fit over all the patch's points in the adopted one: 1 where the scale
  // choice kept it, 0 where it took a smaller patch's, between where the soft choice blended
  // (a patch bent by detail reads below 1).
  double large_weight = 1.0;
  int facing_away = 0;  // of the nearest points, left out as facing away (sheet_fit's facing)
  double patch_radius() const { return inv_r > 0.0 ? 1.0 / inv_r : 0.0; }
  SheetFit at(const Vec3d& y) const;
};
SheetModel sheet_model(const NearbyPoints& near, const Vec3d& x, const Vec3d& n, int k, int k_height, double min_band,
                       HeightNoise noise = {}, std::span<const Vec3f> facing = {});
// sheet_fit's plane part alone (its k nearest points only): bit for bit sheet_fit(...).plane
// without facing (with it, of the k nearest only those facing n, where sheet_fit's plane takes
// the first k facing n of its max(k, k_height) nearest).
LocalFit sheet_plane(const NearbyPoints& near, const Vec3d& x, const Vec3d& n, int k, double min_band,
                     std::span<const Vec3f> facing = {});

struct PointFitFieldOptions {
  int neighbors = 8;  // k
  ProgressHook progress;
};

struct PointFitFieldResult {
  std::vector<LocalFit> fits;  // one per active voxel of `where`, band value order
  double seconds = 0.0;
};

PointFitFieldResult point_fit_field(const PointIndex& index, const NarrowBand& where,
                                    const PointFitFieldOptions& options);

}  // namespace levelset::apps
