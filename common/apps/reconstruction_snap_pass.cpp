// reconstruct_surface's snap pass (reconstruction_snap_pass.hpp).
#include "apps/reconstruction_snap_pass.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "apps/nearby_points.hpp"
#include "apps/reconstruction_parts.hpp"
#include "grid/for_each_active_parallel.hpp"
#include "grid/topology_guard.hpp"

namespace levelset::apps::detail {

namespace {

// Calls f(|dx| + |dy| + |dz|, value index) for every active voxel of the 3x3x3 block around c
// (c itself included, with 0).
template <typename F>
void for_each_active_neighbour27(const NarrowBand& band, BandAccessor& acc, const Coord& c, F&& f) {
  for (int dz = -1; dz <= 1; ++dz)
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
        const Coord q{c.x + dx, c.y + dy, c.z + dz};
        const std::uint32_t qb = acc.locate(brick_of(q));
        if (qb == kNoBrick) continue;
        const Brick& br = band.bricks()[qb];
        const int qn = local_index(q);
        if (!br.active.test(qn)) continue;
        f(std::abs(dx) + std::abs(dy) + std::abs(dz), br.value_offset + br.slot(qn));
      }
}

// Bound on the fits' curvature correction (voxels): a neighbourhood wrapping round a thin
// part is no local patch. 0.5 measured best on the knot (0.25: bias under k = 24, 1: noise).
constexpr double kMaxCorrection = 0.5;
// Snap fits keep the points within max(3 sigma, this many voxels) of the near sheet along the
// normal (apps/point_distance.hpp one_sided_fit): 2 measured better than 1 on the noisy cases
// of bench_reconstruct (and the same genus); no trimming gave the bunny's ear a handle.
constexpr double kOneSidedBand = 2.0;
// Extra smoothing passes of the snap offsets under noise sigma (voxels): round(gain sigma^2),
// at most kMaxSmoothing. The heat-equation scale (time sigma^2 / 2, a 3x3x3 box pass ~ h^2 / 3)
// would give gain 1.5; the fits' noise is spread over their neighbourhoods, so more passes
// pay: 4 measured best on bench_reconstruct's noisy cases (0.2%: 2-3 passes at the final
// level), 0 passes on its clean ones.
constexpr double kSmoothingGain = 4.0;
// The fits leave out the points facing away from the front (point_facing) among those within
// max(kFacingDepth voxels, kFacingNoiseDepth sigma) of it: a thin part's far side lies within
// its noise of the front's far side. Deeper points keep no facing, so every fit takes them: the
// walls of a hole that the front spans (CGAL's turbine, 50k clean points: with no depth bound
// the plugs' fits left out the walls' points and stayed on the plate's faces, and the web
// tunnels opened 2 of the bolt holes, genus 3; with this bound genus 5, as without facing).
// 0.5 and 1 voxel were tried there (1: genus 3).
constexpr double kFacingDepth = 0.5;
constexpr double kFacingNoiseDepth = 3.0;
// The redone noise correction's change is at most this many of the pass's own noise sigmas
// (as the fit's own bound, sheet_fit.cpp).
constexpr double kMaxNoiseShiftRedo = 0.5;

// Step 1 of a pass: the front offset e = clamp(s - u, +-h) of every voxel within the window
// (the plane fit's, and the height fit's where it passes the guard), with the per-brick sums
// the pass's readings come from.
struct FrontOffsets {
  std::vector<float> offset;         // plane fits (NaN: no fit)
  std::vector<std::uint8_t> moves;   // within the window
  std::vector<float> height_offset;  // the height fit's, or the plane's
  std::vector<double> spread;        // per brick: sum of the fits' spread
  std::vector<std::uint32_t> fitted, heights, models;  // per brick: fits, usable height fits, models made
  std::vector<double> residual;      // per brick: sum of the height fits' residuals
  std::vector<double> large_weight;  // per brick: sum of the height fits' large_weight
  std::vector<std::uint32_t> facing_fits;  // per brick: fits that left out points facing away
  // Noisy data: each height fit's offset from the front before the clamp, and its noise gain
  // (SheetFit::noise_gain), to redo the noise correction with the pass's own noise.
  std::vector<float> raw_second, gain;
};

FrontOffsets front_offsets(const NarrowBand& band, const PointIndex& index, const SnapSettings& settings,
                           const NarrowBand& coarse, const std::vector<float>& coarse_curvature,
                           const ProgressHook& progress) {
  const double h = band.voxel_size();
  const double window = settings.window, fit_window = std::min(settings.fit_window, settings.window);
  const int neighbors = settings.neighbors;
  const bool same_grid = coarse.voxel_size() == h;  // a single level: its own curvature
  const float unset = std::numeric_limits<float>::quiet_NaN();
  FitSettings fit_settings = snap_fit_settings(neighbors, settings.height_neighbors, kOneSidedBand * h, h,
                                                     {settings.noise, settings.noisy_height, settings.soft_scales},
                                                     settings.wide_blocks);
  // Which way the points face, from the band before the pass (reconstruction_parts.hpp).
  const std::vector<Vec3f> facing = settings.facing_points
                                        ? point_facing(band, index, std::max(kFacingDepth * h, kFacingNoiseDepth * settings.noise))
                                        : std::vector<Vec3f>{};
  fit_settings.facing = facing;
  FitSettings widened_settings = fit_settings;
  widened_settings.height_neighbors = std::max(settings.height_neighbors, settings.widened_neighbors);
  FrontOffsets out;
  out.offset.assign(band.active_voxel_count(), unset);
  out.moves.assign(band.active_voxel_count(), 0);
  out.height_offset.assign(band.active_voxel_count(), unset);
  for (auto* v : {&out.spread, &out.residual, &out.large_weight}) v->assign(band.brick_count(), 0.0);
  for (auto* v : {&out.fitted, &out.heights, &out.models, &out.facing_fits}) v->assign(band.brick_count(), 0);
  if (settings.noisy_height) {
    out.raw_second.assign(band.active_voxel_count(), unset);
    out.gain.assign(band.active_voxel_count(), 0.0f);
  }
  auto& [offset, moves, height_offset, spread, fitted, heights, models, residual, large_weight, facing_fits, raw_second,
         gain] = out;
  tbb::parallel_for(tbb::blocked_range<std::uint32_t>(0, std::uint32_t(band.brick_count()), 8),
                    [&](const tbb::blocked_range<std::uint32_t>& r) {
                      progress.check("reconstruct snap");
                      BandAccessor acc(band), coarse_acc(coarse);
                      NearbyPoints near(index);
                      std::vector<FitVoxel> voxels;
                      std::vector<SheetFit> fits;
                      for (std::uint32_t b = r.begin(); b != r.end(); ++b) {
                        if (settings.only && !std::binary_search(settings.only->begin(), settings.only->end(),
                                                                 brick_key(band.bricks()[b].coord)))
                          continue;
                        const bool widened = settings.widen && std::binary_search(settings.widen->begin(), settings.widen->end(),
                                                                                  brick_key(band.bricks()[b].coord));
                        const FitSettings& fs = widened ? widened_settings : fit_settings;
                        prepare_brick_neighbours(band, b, fit_window * h, std::max(neighbors, fs.height_neighbors), near);
                        std::size_t slot = band.bricks()[b].value_offset;
                        const Coord origin = brick_origin(band.bricks()[b].coord);
                        voxels.clear();
                        band.for_each_active_in_brick(b, [&](const Coord& c, float value) {
                          const std::size_t i = slot++;
                          const double u = double(value);
                          if (!(std::abs(u) < window * h)) return;
                          moves[i] = 1;
                          if (!(std::abs(u) < fit_window * h)) return;
                          const Vec3d g{double(acc.value(c + Coord{1, 0, 0})) - double(acc.value(c - Coord{1, 0, 0})),
                                        double(acc.value(c + Coord{0, 1, 0})) - double(acc.value(c - Coord{0, 1, 0})),
                                        double(acc.value(c + Coord{0, 0, 1})) - double(acc.value(c - Coord{0, 0, 1}))};
                          const double gl = length(g);
                          if (!(gl > 1e-6)) return;
                          // The coarse level's curvature: smooth, where the fine one's
                          // second differences would feed the fits' noise back.
                          double H = same_grid ? field_at(coarse_acc, coarse, coarse_curvature, c)
                                               : coarse_field_at(coarse_acc, coarse, coarse_curvature, c);
                          if (!std::isfinite(H)) H = 0.0;
                          // The column along the normal's dominant axis: its voxels see the
                          // same points (fit_voxels).
                          const Coord l = c - origin;
                          const int axis = std::abs(g.x) >= std::abs(g.y) && std::abs(g.x) >= std::abs(g.z) ? 0
                                           : std::abs(g.y) >= std::abs(g.z)                          ? 1
                                                                                                    : 2;
                          const int across = axis == 0 ? l.y | l.z << 3 : axis == 1 ? l.x | l.z << 3 : l.x | l.y << 3;
                          voxels.push_back({i, band.world(c), g / gl, H, u, axis << 6 | across});
                        });
                        models[b] = std::uint32_t(fit_voxels(near, voxels, fs, fits));
                        for (std::size_t v = 0; v < voxels.size(); ++v) {
                          const FitVoxel& fv = voxels[v];
                          const SheetFit& sf = fits[v];
                          const LocalFit& fit = sf.plane;
                          const double plane = fit.signed_offset(fv.n, fv.H, kMaxCorrection * h);
                          double second = plane;
                          if (sf.has_height && std::abs(sf.height_offset - plane) <= settings.height_guard * h) {
                            second = sf.height_offset;
                            residual[b] += sf.height_residual;
                            large_weight[b] += sf.large_weight;
                            ++heights[b];
                            if (settings.noisy_height) {
                              raw_second[fv.i] = float(second - fv.u);
                              gain[fv.i] = float(sf.noise_gain);
                            }
                          }
                          offset[fv.i] = float(std::clamp(plane - fv.u, -h, h));
                          height_offset[fv.i] = float(std::clamp(second - fv.u, -h, h));
                          spread[b] += double(fit.spread);
                          ++fitted[b];
                          facing_fits[b] += sf.facing_away > 0;
                        }
                      }
                    });
  return out;
}

// One 3x3x3 box pass over the offsets of the voxels that move (NaN: no offset, skipped).
std::vector<float> box_smoothed(const NarrowBand& band, const std::vector<float>& offset,
                                const std::vector<std::uint8_t>& moves) {
  std::vector<float> smoothed(offset.size(), std::numeric_limits<float>::quiet_NaN());
  for_each_active_parallel(band, band, 8, [&](BandAccessor& acc, std::uint32_t, const Coord& c, float, std::size_t i) {
    if (!moves[i]) return;
    double sum = 0.0;
    int n = 0;
    for_each_active_neighbour27(band, acc, c, [&](int, std::size_t j) {
      if (std::isnan(offset[j])) return;
      sum += double(offset[j]);
      ++n;
    });
    if (n > 0) smoothed[i] = float(sum / n);
  });
  return smoothed;
}

// Step 2's move: every voxel that moves takes the mean offset of its 3x3x3 neighbourhood (the
// voxel and its 6 face neighbours only on clean data); only voxels next to the front may
// change sign. values: the band's new values; change, count: per brick, the sum of |change|
// (voxels) and the voxels moved.
struct MovedFront {
  std::vector<float> values;
  std::vector<double> change;
  std::vector<std::uint32_t> count;
};

MovedFront moved_front(const NarrowBand& band, const std::vector<float>& offset, const std::vector<std::uint8_t>& moves,
                       bool clean) {
  const double h = band.voxel_size();
  MovedFront out{std::vector<float>(band.values().begin(), band.values().end()),
                 std::vector<double>(band.brick_count(), 0.0), std::vector<std::uint32_t>(band.brick_count(), 0)};
  std::vector<float>& next = out.values;
  std::vector<double>& change = out.change;
  std::vector<std::uint32_t>& count = out.count;
  for_each_active_parallel(band, band, 8, [&](BandAccessor& acc, std::uint32_t b, const Coord& c, float value, std::size_t i) {
    if (!moves[i]) return;
    const double u = double(value);
    const bool inside = u < 0.0;
    bool at_front = false;
    double sum = 0.0;
    int n = 0;
    for_each_active_neighbour27(band, acc, c, [&](int taxicab, std::size_t j) {
      if (taxicab == 1 && (band.values()[j] < 0.0f) != inside) at_front = true;
      if (std::isnan(offset[j])) return;
      if (clean && taxicab > 1) return;
      sum += double(offset[j]);
      ++n;
    });
    if (n == 0) return;
    double target = u + sum / n;
    if (!at_front && (target < 0.0) != inside) target = inside ? -1e-3 * h : 1e-3 * h;
    next[i] = float(target);
    change[b] += std::abs(target - u) / h;
    ++count[b];
  });
  return out;
}

}  // namespace

// One snap pass (apps/reconstruction.hpp describes it): every voxel with |u| < window h takes
// the signed offset s of its local fit along the level set's normal, moved by at most one
// voxel. Per-brick sums added in brick order (deterministic).
SnapPass snap_to_fits(NarrowBand& band, const PointIndex& index, const SnapSettings& settings, const NarrowBand& coarse,
                      const std::vector<float>& coarse_curvature, const ProgressHook& progress) {
  const double h = band.voxel_size();
  FrontOffsets fronts = front_offsets(band, index, settings, coarse, coarse_curvature, progress);
  auto& [offset, moves, height_offset, spread, fitted, heights, models, residual, large_weight, facing_fits, raw_second,
         gain] = fronts;
  // 2. Each voxel moves by the mean offset of its 3x3x3 neighbourhood: the offset is nearly
  // constant along normals, so this averages the fits tangentially (their noise / ~3).
  // Only voxels next to the front may change sign: no new bubbles or handles away from it
  // (the coarse level fixed the topology).
  // 2a. Noise: the offsets are smoothed tangentially by `smoothing` more 3x3x3 box passes
  // (each adds ~2/3 h^2 of variance per axis, a heat-equation time of ~1/3 h^2), their
  // number set by the mean noise estimate sigma of the fits (kSmoothingGain); none on clean
  // data, where it would only blur.
  double sigma_sum = 0.0, residual_sum = 0.0;
  std::uint64_t sigma_n = 0, height_n = 0;
  for (std::size_t b = 0; b < spread.size(); ++b) {
    sigma_sum += spread[b];
    sigma_n += fitted[b];
    height_n += heights[b];
    residual_sum += residual[b];
  }
  const double sigma = settings.fixed_sigma >= 0.0 ? settings.fixed_sigma : sigma_n > 0 ? sigma_sum / double(sigma_n) / h : 0.0;
  // Noisy data: the fits were corrected for the noise the previous pass read; this pass's
  // height fits, selected for noise, read it better (the previous level, without the
  // selection, read ~0.85 of it): the correction redone with this pass's mean residual.
  // bench_reconstruct --sweep, 20k / 0.5 %: 5 cases 1-3 % better (man 1.153 -> 1.124), none
  // worse; 20k / 0.1 % unchanged.
  if (settings.noisy_height && height_n > 0) {
    const double mean = settings.fixed_residual >= 0.0 ? settings.fixed_residual : residual_sum / double(height_n), residual_floor = kResidualFloor * settings.h_final;
    const double own = std::sqrt(std::max(0.0, mean * mean - residual_floor * residual_floor));
    const double more = own * own - settings.noise * settings.noise, bound = kMaxNoiseShiftRedo * own;
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, raw_second.size(), 1 << 14),
                      [&](const tbb::blocked_range<std::size_t>& r) {
                        for (std::size_t i = r.begin(); i != r.end(); ++i) {
                          if (std::isnan(raw_second[i])) continue;
                          const double extra = std::clamp(double(gain[i]) * more, -bound, bound);
                          height_offset[i] = float(std::clamp(double(raw_second[i]) + extra, -h, h));
                        }
                      });
  }
  // 2b. Clean data (see kCleanNoise): the height fits' offsets, averaged over face neighbours below.
  const bool clean = sigma * h < kCleanNoise * settings.h_final;
  if (clean || settings.noisy_height) offset.swap(height_offset);
  std::vector<float>().swap(height_offset);
  const int smoothing = clean                    ? 0
                        : settings.noisy_height ? int(std::min<long>(1, std::lround(sigma * sigma)))
                                                : int(std::min<long>(kMaxSmoothing, std::lround(kSmoothingGain * sigma * sigma)));
  for (int smooth = 0; smooth < smoothing; ++smooth) offset = box_smoothed(band, offset, moves);
  MovedFront moved = moved_front(band, offset, moves, clean);
  std::vector<float>& next = moved.values;
  const std::vector<double>& change = moved.change;
  const std::vector<std::uint32_t>& count = moved.count;
  std::uint64_t refused = 0;
  if (settings.guard) {
    TopologyGuardOptions guard;
    guard.eps = 1e-3 * h;
    guard.progress = progress;
    // After a sheet was cut (settings.cut_zone): the flips connected to it may cut the inside.
    std::vector<std::uint64_t> cuttable;
    if (settings.cut_zone && !settings.cut_zone->empty()) {
      cuttable = cutting_reach(band, next, *settings.cut_zone);
      guard.cuttable = [&cuttable](const Coord& c) {
        return std::binary_search(cuttable.begin(), cuttable.end(), key_of(c));
      };
    }
    TopologyGuardResult kept = guard_topology(band, band, std::move(next), guard);
    refused = kept.refused_flips;
    band.swap_values(kept.values);
    if (!cuttable.empty()) drop_web_scraps(band, cuttable);
  } else {
    band.swap_values(next);
  }
  SnapPass pass;
  pass.refused = refused;
  pass.noise = sigma;
  pass.height_noise = height_n > 0 ? residual_sum / double(height_n) / h : 0.0;
  pass.smoothing = smoothing;
  pass.clean = clean;
  pass.height_fits = height_n;
  for (const std::uint32_t m : models) pass.models += m;
  for (const std::uint32_t f : facing_fits) pass.facing_fits += f;
  for (std::size_t b = 0; b < change.size(); ++b) {
    pass.mean_change += change[b];
    pass.voxels += count[b];
    if (settings.moved_limit > 0.0 && count[b] > 0 && change[b] > settings.moved_limit * double(count[b]))
      pass.moved.push_back(brick_key(band.bricks()[b].coord));
  }
  std::sort(pass.moved.begin(), pass.moved.end());
  if (settings.soft_scales)
    for (std::size_t b = 0; b < heights.size(); ++b)
      if (heights[b] > 0 && large_weight[b] >= kWidenWeight * double(heights[b]))
        pass.smooth.push_back(brick_key(band.bricks()[b].coord));
  std::sort(pass.smooth.begin(), pass.smooth.end());
  if (pass.voxels > 0) pass.mean_change /= double(pass.voxels);
  return pass;
}

}  // namespace levelset::apps::detail
