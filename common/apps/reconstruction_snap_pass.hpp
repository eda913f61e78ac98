// reconstruct_surface's snap pass (reconstruction_snap.cpp's levels run it): every voxel near
// the front takes the offset of its local fits (reconstruction_fits.cpp), averaged over its
// neighbourhood and guarded against topology changes. Internal to apps/reconstruction*.cpp.
// Inputs: the band (world distances), the points' index, SnapSettings (the fits' point counts,
// noise model, windows, the bricks it may touch), the coarser level's band and mean curvature
// (the plane fits' curvature correction). Output: the band moved in place; SnapPass (the
// pass's noise readings, mean change, per-brick lists for later passes). Cost: one sheet fit
// per column or block of voxels within the fit window (fit_voxels), O(window voxels) else.
// Threading: TBB over bricks; per-brick sums added in brick order (deterministic).
#pragma once

#include <cstdint>
#include <vector>

#include "apps/reconstruction_parts.hpp"

namespace levelset::apps::detail {

// Snap: voxels within this many voxels of the front take their fit's offset (the marching
// cubes read |u| < 1 h; the margin covers the front's move).
inline constexpr double kSnapWindow = 1.5;
// Voxels within this many voxels of the front compute fits on a first pass; the others in the
// snap window take their neighbours' mean offset (the offset is nearly constant along the
// normal; bench_reconstruct: the same Chamfer as fits on the whole window, 15% faster).
inline constexpr double kFitWindow = 1.0;
// Second-order snap fits (point_distance.hpp sheet_fit): at least this many points per height
// fit (a quadric has 6 unknowns; on bench_reconstruct's clean cases 12-16 measured best, 30+
// worse: the quadric no longer describes the larger patch), used where they agree with the
// plane fit within kHeightGuard voxels, or kHeightGuardNoise times the noise the previous
// pass measured (height fits' residual) where that is more: the two fits' offsets differ by
// their noise as well, and under 0.5 % noise (1.5-1.7 final voxels) a one-voxel guard sent a
// third of the voxels back to the plane fit, over `neighbors` (8) points against the height
// fit's 60-100: a noisy sphere's RMS error 0.35 -> 0.30 sigma; bench_reconstruct --sweep, 20k
// points, 0.5 % noise: median ratio to Poisson's Chamfer 0.979 -> 0.919.
inline constexpr int kHeightNeighbors = 16;
inline constexpr double kHeightGuard = 1.0;
inline constexpr double kHeightGuardNoise = 2.0;
// Data are "clean" when the fits' mean noise estimate is below this many final voxels: then
// the snap takes the height fits' offsets averaged over the voxel and its 6 face neighbours
// only (unbiased fits: the 3x3x3 averaging blurred them, costing bench_reconstruct's clean
// cases a factor 1.5-2.5 in Chamfer; no averaging at all was as accurate but its second
// pass gave the bunny with 20k points 7 handles); otherwise the plane fits, 3x3x3-averaged
// and smoothed (the quadric's variance under noise made the noisy cases 10-40% worse).
// Measured: clean 0.04-0.17 voxels, 0.2% noise 0.6-0.8.
inline constexpr double kCleanNoise = 0.4;
inline constexpr long kMaxSmoothing = 3;
// The height fits' residual on clean points (the quadric's third-order misfit, float
// positions): 0.01-0.03 final voxels measured; residuals are counted as noise beyond it.
inline constexpr double kResidualFloor = 0.1;
// A later pass on the same level widens the soft-scale height fits by kWidenGrowth in the
// bricks where the pass before kept the largest of its three patches with a mean weight of at
// least kWidenWeight (SnapPass::smooth): there the data asked for the largest patch, so a
// larger one averages more of the noise; where detail made the blend fall back to smaller
// patches the count stays. In practice the clean route's second final pass under mild noise
// (bench_reconstruct --sweep, 20k points, 0.1 %: 7 cases change, the ellipsoid -8.7 %, the
// blobbies -5 %, bear -2.0 %, bear_bis -1.9 %, triceratops +0.1 %; median ratio to Poisson's
// Chamfer 0.829 -> 0.813). Weights 0.5 / 0.4 / 0.3 / 0.2: median 0.820 / 0.813 / 0.811 / 0.810,
// homer +0.5 % at 0.2; a growth of 2 instead of 5/3 the same within 1 %, most fits at the
// 256-point cap. (Over the whole band, a growth of 4/3 or 5/3 took the median to 0.819 / 0.809
// but cost armadillo and homer 1.4-2.4 % and their wins, where the mean weight reads 0.26-0.33
// against 0.43-0.61 on the smooth shapes.)
inline constexpr double kWidenWeight = 0.4;
inline constexpr double kWidenGrowth = 5.0 / 3.0;

struct SnapPass {
  double mean_change = 0.0;     // voxels, over the snapped voxels
  double noise = 0.0;           // mean robust spread of the fits, voxels
  double height_noise = 0.0;    // mean residual of the height fits (noise without sagitta), voxels
  int smoothing = 0;            // extra smoothing passes of the offsets
  bool clean = false;           // the height fits' offsets were used, unaveraged
  std::uint64_t voxels = 0;     // snapped (fits computed)
  std::uint64_t models = 0;     // sheet fits made for them (fit_voxels)
  std::uint64_t height_fits = 0;  // of them with a usable height fit
  std::uint64_t refused = 0;    // sign changes refused (not simple: they would change the topology)
  std::uint64_t facing_fits = 0;  // fits that left out points facing away (SnapSettings::facing_points)
  std::vector<std::uint64_t> moved;  // brick_key (sorted) of the bricks whose voxels moved more than settings.moved_limit on average
  // brick_key (sorted) of the bricks whose soft-scale height fits kept their largest patch
  // with a mean weight of at least kWidenWeight (soft_scales passes only).
  std::vector<std::uint64_t> smooth;
};

struct SnapSettings {
  int neighbors = 8;             // plane fits
  int height_neighbors = kHeightNeighbors;  // height fits
  double height_guard = kHeightGuard;  // voxels: height fits within this of the plane fit's are used
  bool noisy_height = false;     // noisy data: the height fits' offsets as well (see kNoisyHeightNeighbors)
  bool soft_scales = false;      // the height fits' soft three-scale patch choice (kSoftScaleGrowth)
  bool wide_blocks = false;      // noise above kReferenceNoise: fits shared over 4x4 blocks (reconstruction_fits.cpp)
  double noise = 0.0;            // world: the points' noise the previous pass measured, beyond kResidualFloor
  double window = kSnapWindow;   // voxels that move
  double fit_window = kFitWindow;  // voxels with their own fit (within the window)
  double h_final = 0.0;
  bool guard = true;             // keep the topology
  const std::vector<std::uint64_t>* only = nullptr;  // when set: only voxels of these bricks (brick_key, sorted) move
  double moved_limit = 0.0;      // voxels; > 0: SnapPass::moved lists the bricks that moved more
  // >= 0: the noise readings a pass on some bricks (`only`) takes from the full pass before it:
  // the fits' mean spread (voxels) and the height fits' mean residual (world). Its own fits'
  // would read the detail of the bricks chosen for it as noise.
  double fixed_sigma = -1.0, fixed_residual = -1.0;
  // When set: the height fits of these bricks (brick_key, sorted) take widened_neighbors points.
  const std::vector<std::uint64_t>* widen = nullptr;
  int widened_neighbors = 0;
  bool facing_points = true;     // fits leave out the points facing away from the front (point_facing)
  // When set: voxel keys (sorted) where the guard also takes flips that only cut the inside
  // (CarveOutput::cut_zone, guard rule 1b).
  const std::vector<std::uint64_t>* cut_zone = nullptr;
};

// One snap pass (apps/reconstruction.hpp describes it): every voxel with |u| < window h takes
// the signed offset s of its local fit along the level set's normal, moved by at most one
// voxel. Per-brick sums added in brick order (deterministic).
SnapPass snap_to_fits(NarrowBand& band, const PointIndex& index, const SnapSettings& settings, const NarrowBand& coarse,
                      const std::vector<float>& coarse_curvature, const ProgressHook& progress);

}  // namespace levelset::apps::detail
