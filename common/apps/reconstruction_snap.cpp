// reconstruct_surface's finer levels: the snap of the front onto the points' local fits
// (reconstruction_parts.hpp).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "apps/reconstruction_parts.hpp"
#include "apps/reconstruction_snap_pass.hpp"
#include "distance/redistance.hpp"
#include "grid/band_accessor.hpp"
#include "grid/band_builder.hpp"
#include "grid/for_each_active_parallel.hpp"

namespace levelset::apps::detail {

namespace {

// Later passes after a clean one: the front moved by ~0.01-0.1 voxel, so only the voxels the
// redistance keeps (interface voxels, |u| < h) and the marching cubes read need a new fit
// (same Chamfer on bench_reconstruct as 1.5, a third fewer fits).
constexpr double kRefineWindow = 1.0;
// Noisy data, after a first noisy level: the snap takes the height fits too, over a larger
// patch: kNoisyHeightNeighbors points at kReferenceDensity points per final voxel^2, scaled by
// (density / reference)^(3/4) (the patch radius r minimising bias ~ r^3 against variance
// ~ sigma^2 / (density r^2) goes as sigma^(1/4) density^(-1/8), so the count density r^2 as
// sigma^(1/2) density^(3/4)), with one smoothing pass at most. bench_reconstruct, noisy cases:
// 48 points best at 20k (Chamfer -11% against the plane fits), 160 at 100k (-8%); the scaling
// law gives 3.3 for a 5x density, as measured. Above kReferenceNoise (the height fits'
// residual) the count grows in proportion to noise / reference; the law's sqrt measured
// worse once the height fits carried the noisy snaps (kHeightGuardNoise): at 0.5 % noise,
// 20k points, median ratio to Poisson's Chamfer 0.919 -> 0.870 (wins 20 -> 22 of 33), the 0.1 %
// rows (noise below the reference) unchanged. Before that, sqrt(noise / reference) against
// none, bench_reconstruct --sweep at 0.5 % noise, 20k points: 15 -> 20 of 33 cases at or below Poisson's Chamfer, median ratio
// 1.009 -> 0.977; 50k: 21 cases better, none worse. Below it the count stays (the law's
// smaller patches: 50k / 0.1 %, 9 cases worse and 3 better, median 0.761 -> 0.783).
constexpr int kNoisyHeightNeighbors = 48;
// Where the height fits' residual lies between kSoftScaleMinNoise and kReferenceNoise, the
// fits take kSoftScaleGrowth times the count law's points and blend the fits over all, the
// nearer half and the nearer quarter of them by their estimated bias and variance
// (point_distance.hpp HeightNoise::soft; README round 13: 20k / 0.1 % median 0.887 -> 0.839).
constexpr int kSoftScaleGrowth = 3;
// The lower bound (final voxels): there the residual is noise, not the
// quadric's misfit on clean data (0.03-0.16 on bench_reconstruct --sweep's clean meshes, where
// more points cost the featured ones 10-20 %: anchor, hand, elephant, turbine at 20k; 0.3-0.45
// at 0.1 % noise).
constexpr double kSoftScaleMinNoise = 0.25;
constexpr double kReferenceDensity = 0.15;
constexpr double kDensityExponent = 0.75;
// The noise (final voxels) at which kNoisyHeightNeighbors was measured best (0.2% noise).
constexpr double kReferenceNoise = 0.7;
// A level's snap restarts when its first pass's noise reading asks for this many times the
// height fits' points (snap_level).
constexpr int kRestartGrowth = 4;
// Snap passes, before the level's own, on the bricks where gaps were carved
// (reconstruction_carve.cpp): the new walls lie about the clearance (2-3 voxels) off their
// points, and a snap moves the front by at most a voxel per pass.
constexpr int kPassesAfterCarving = 2;
// Noisy data get one snap pass per level: each voxel moves by its 3x3x3 neighbourhood's mean
// offset, which removes the smooth part of the front's distance to its fits and leaves the
// rest, so where the upsampled front started far from them (detail the middle level could not
// follow) one pass stops short. On the final level the bricks whose voxels moved by more than
// kRefitChange voxels on average take one more pass (ReconstructionOptions::refit_moved;
// armadillo at 50k points and 0.1 % noise: a second pass over all bricks took its
// truth-to-surface mean distance 0.198 -> 0.186 voxel, one over the 29 % that moved more than
// 0.1 voxel 0.188; bench_reconstruct --sweep at 20k points, 0.1 %, on 10 detailed meshes:
// limits 0.1, 0.15, 0.25 -3.0, -3.0, -2.5 % median, and the least time with 0.25). Only
// under mild noise (the height fits' residual at most kReferenceNoise final voxels): under
// strong noise the first pass's large moves are the fits' noise, which a second pass only
// adds to (20k points, 0.5 % noise: 21 of 33 CGAL meshes worse, median +1.3 %, 19 % more time).
constexpr double kRefitChange = 0.25;

// Mean curvature H = div(grad u / |grad u|) by central differences (u a distance, so the
// 1 / |grad u|^3 normalisation is near 1); the 18 neighbours must be in the band.
double central_mean_curvature(BandAccessor& acc, const Coord& c, double u, double h, Vec3d& gradient) {
  auto at = [&](int dx, int dy, int dz) { return double(acc.value(Coord{c.x + dx, c.y + dy, c.z + dz})); };
  const double xp = at(1, 0, 0), xm = at(-1, 0, 0), yp = at(0, 1, 0), ym = at(0, -1, 0), zp = at(0, 0, 1),
               zm = at(0, 0, -1);
  const double ux = (xp - xm) / (2 * h), uy = (yp - ym) / (2 * h), uz = (zp - zm) / (2 * h);
  gradient = {ux, uy, uz};
  const double g2 = ux * ux + uy * uy + uz * uz;
  if (g2 < 1e-12) return 0.0;
  const double uxx = (xp - 2 * u + xm) / (h * h), uyy = (yp - 2 * u + ym) / (h * h), uzz = (zp - 2 * u + zm) / (h * h);
  const double uxy = (at(1, 1, 0) - at(1, -1, 0) - at(-1, 1, 0) + at(-1, -1, 0)) / (4 * h * h);
  const double uxz = (at(1, 0, 1) - at(1, 0, -1) - at(-1, 0, 1) + at(-1, 0, -1)) / (4 * h * h);
  const double uyz = (at(0, 1, 1) - at(0, 1, -1) - at(0, -1, 1) + at(0, -1, -1)) / (4 * h * h);
  const double num = uxx * (uy * uy + uz * uz) + uyy * (ux * ux + uz * uz) + uzz * (ux * ux + uy * uy) -
                     2.0 * (ux * uy * uxy + ux * uz * uxz + uy * uz * uyz);
  return num / (g2 * std::sqrt(g2));
}

// H of every active voxel of the band (band value order), clamped to +-1 / h; voxels whose
// stencil leaves the band read the band limit (their H is only used far from the front).
std::vector<float> mean_curvature_field(const NarrowBand& band) {
  const double h = band.voxel_size();
  std::vector<float> H(band.active_voxel_count());
  for_each_active_parallel(band, band, 8, [&](BandAccessor& acc, std::uint32_t, const Coord& c, float u, std::size_t slot) {
    Vec3d g;
    H[slot] = float(std::clamp(central_mean_curvature(acc, c, double(u), h, g), -1.0 / h, 1.0 / h));
  });
  return H;
}

// The front's sampling density: points per final voxel^2 of front, the front's area the count
// of voxels within half a voxel of it (a distance's slab of one voxel's thickness); 0 when the
// band has no such voxel.
double front_density(const NarrowBand& band, std::size_t points, double h_final) {
  const float half = float(0.5 * band.voxel_size());
  std::uint64_t slab = 0;
  for (const float v : band.values())
    if (std::abs(v) < half) ++slab;
  if (slab == 0) return 0.0;
  const double ratio = h_final / band.voxel_size();
  return double(points) / double(slab) * ratio * ratio;
}

// The height fits' point count (see kNoisyHeightNeighbors) at a density (points per final
// voxel^2) and, on clean data, a noise (final voxels): the patch radius minimising bias ~ r^3
// against variance ~ sigma^2 / (density r^2) goes as sigma^(1/4) density^(-1/8), so the count
// as sigma^(1/2) density^(3/4); kNoisyHeightNeighbors at kReferenceNoise. `noise` is the
// height fits' residual (no sagitta), counted beyond kResidualFloor. Never below
// kHeightNeighbors (clean data: 16 measured best; 24 cost the clean blobby 20 %). growth
// multiplies the law's count before that floor (kSoftScaleGrowth under the soft scale choice).
int height_neighbors_for(double density, double noise, int growth) {
  if (!(density > 0.0)) return kNoisyHeightNeighbors;
  const double excess = std::sqrt(std::max(0.0, noise * noise - kResidualFloor * kResidualFloor));
  const double k = growth * kNoisyHeightNeighbors * std::pow(density / kReferenceDensity, kDensityExponent) *
                   std::sqrt(excess / kReferenceNoise);
  return int(std::clamp(std::lround(k), long(kHeightNeighbors), 256L));
}

int noisy_height_neighbors(const NarrowBand& band, std::size_t points, double h_final, double noise) {
  const double density = front_density(band, points, h_final);
  if (!(density > 0.0)) return kNoisyHeightNeighbors;
  double k = kNoisyHeightNeighbors * std::pow(density / kReferenceDensity, kDensityExponent);
  // Noisier than the reference: more points, in proportion to the noise (see kNoisyHeightNeighbors).
  // Below it the reference count stays: the law's smaller patches measured worse there.
  k *= std::max(1.0, noise / kReferenceNoise);
  return int(std::clamp(std::lround(k), long(kNoisyHeightNeighbors) / 2, 256L));
}

// The settings of a snap pass on `band` (voxel size h) from the noise the previous pass read
// (final voxels): the height fits' point count and noise model (see kNoisyHeightNeighbors,
// kSoftScaleGrowth), their guard against the plane fits, and the window.
SnapSettings snap_settings(const ReconstructionOptions& o, const NarrowBand& band, std::size_t points,
                           SnapNoise previous, double h, double h_final, bool refine) {
  const double previous_noise = previous.noise, previous_height_noise = previous.height_noise;
  SnapSettings settings;
  settings.neighbors = o.neighbors;
  // Noise between kSoftScaleMinNoise and the reference: the fits take kSoftScaleGrowth
  // times the count law's points and choose the patch by the soft three-scale rule
  // (sheet_fit's HeightNoise::soft).
  settings.soft_scales = previous_height_noise >= kSoftScaleMinNoise && previous_height_noise <= kReferenceNoise;
  settings.wide_blocks = previous_height_noise > kReferenceNoise;
  const int growth = settings.soft_scales ? kSoftScaleGrowth : 1;
  settings.height_neighbors = std::max(o.neighbors, kHeightNeighbors);
  if (previous_noise >= kCleanNoise) {
    settings.noisy_height = true;
    settings.height_neighbors =
        std::max(settings.height_neighbors,
                 std::min(256, growth * noisy_height_neighbors(band, points, h_final, previous_height_noise)));
  } else if (previous_height_noise > 0.0) {  // clean so far: more points as the noise grows
    settings.height_neighbors = std::max(
        settings.height_neighbors, height_neighbors_for(front_density(band, points, h_final), previous_height_noise, growth));
  }
  settings.height_guard = std::max(kHeightGuard, kHeightGuardNoise * previous_height_noise * h_final / h);
  settings.noise = std::sqrt(std::max(0.0, previous_height_noise * previous_height_noise -
                                               kResidualFloor * kResidualFloor)) * h_final;
  settings.window = refine ? kRefineWindow : kSnapWindow;
  settings.fit_window = refine ? kRefineWindow : kFitWindow;
  settings.h_final = h_final;
  settings.guard = o.guard_snaps;
  settings.facing_points = o.facing_points;
  return settings;
}

// The band redistanced (fast sweeping, half-width W) on its domain less `shrink` voxels
// (snap_level: the domain may grow by the front's motion since the last redistance).
NarrowBand redistanced(const NarrowBand& band, double W, double shrink, const ProgressHook& progress) {
  RedistanceOptions redo;
  redo.half_width = W;
  redo.progress = progress;
  return redistance(reframed(band, {}, W - shrink), redo).band;
}

// Copies brick b of `band` (active voxels, inside bits, values) into `builder`.
void copy_brick(const NarrowBand& band, std::uint32_t b, BandBuilder& builder,
                std::vector<float>& values) {
  const Brick& br = band.bricks()[b];
  std::size_t slot = br.value_offset;
  br.active.for_each_set([&](int n) { values[std::size_t(n)] = band.values()[slot++]; });
  builder.add_brick(br.coord, br.active, band.inside_mask(b), values.data());
}

}  // namespace

NarrowBand redistanced_near(const NarrowBand& band, const std::vector<std::uint64_t>& moved,
                            double W, double shrink, const ProgressHook& progress) {
  auto dilate = [](const std::vector<Coord>& from, int r) {
    std::vector<Coord> out;
    for (const Coord& c : from)
      for (int dz = -r; dz <= r; ++dz)
        for (int dy = -r; dy <= r; ++dy)
          for (int dx = -r; dx <= r; ++dx) out.push_back(c + Coord{dx, dy, dz});
    std::sort(out.begin(), out.end(),
              [](const Coord& a, const Coord& b) { return brick_key(a) < brick_key(b); });
    out.erase(std::unique(out.begin(), out.end()), out.end());
    return out;
  };
  std::vector<Coord> seeds;
  BandAccessor acc(band);
  for (std::uint32_t b = 0; b < band.brick_count(); ++b)
    if (std::binary_search(moved.begin(), moved.end(), brick_key(band.bricks()[b].coord)))
      seeds.push_back(band.bricks()[b].coord);
  if (seeds.empty()) return band;  // nothing moved
  const std::vector<Coord> near = dilate(seeds, 1), context = dilate(near, 2);
  BandBuilder sub_builder(band.frame());
  std::vector<float> values(kBrickVoxels, 0.0f);
  for (const Coord& c : context) {
    const std::uint32_t b = acc.locate(c);
    if (b != kNoBrick) {
      copy_brick(band, b, sub_builder, values);
      continue;
    }
    BrickMask inside{};
    const Coord o = brick_origin(c);
    for (int n = 0; n < kBrickVoxels; ++n) inside.assign(n, acc.is_inside(o + local_coord(n)));
    sub_builder.add_brick(c, BrickMask{}, inside, values.data());
  }
  const NarrowBand redone = redistanced(sub_builder.finish(band.far_inside()), W, shrink, progress);
  auto in_near = [&](const Coord& c) {
    return std::binary_search(near.begin(), near.end(), c, [](const Coord& a, const Coord& b) {
      return brick_key(a) < brick_key(b);
    });
  };
  BandBuilder merged(redone.frame());
  for (std::uint32_t b = 0; b < band.brick_count(); ++b)
    if (!in_near(band.bricks()[b].coord)) copy_brick(band, b, merged, values);
  for (std::uint32_t b = 0; b < redone.brick_count(); ++b)
    if (in_near(redone.bricks()[b].coord)) copy_brick(redone, b, merged, values);
  return merged.finish(band.far_inside());
}

SnapOutput snap_level(NarrowBand band, const PointIndex& index, const ReconstructionOptions& o,
                      const SnapLevel& where, ReconstructionStage stage, SnapNoise previous) {
  const double W = o.half_width, h = stage.voxel_size, h_final = where.h_final;
  const int level = where.level, levels = where.levels;
  double previous_noise = previous.noise, previous_height_noise = previous.height_noise;
  // The snap (on a single level: after the flow, with its own curvature).
  const NarrowBand coarse = std::move(band);
  const std::vector<float> coarse_curvature = mean_curvature_field(coarse);
  const auto t_up = Clock::now();
  band = level > 0 ? upsample(coarse, W, o.progress) : coarse;
  std::vector<std::uint64_t> carved_bricks, cut_zone;
  if (level > 0 && o.carve_gaps) {
    CarveOutput carved = carve_buried_gaps(std::move(band), index, where.carve, o.progress);
    band = std::move(carved.band);
    stage.buried_points = carved.buried;
    stage.carved_regions = carved.regions;
    stage.pierced_regions = carved.pierced_regions;
    stage.webs_cut = carved.webs;
    stage.sheets_cut = carved.cut_sheets;
    stage.web_tunnels = carved.web_tunnels;
    stage.carved_voxels = carved.carved_voxels;
    carved_bricks = std::move(carved.bricks);
    cut_zone = std::move(carved.cut_zone);
  }
  stage.seconds_start += seconds_since(t_up);
  auto settings_for = [&](bool refine) {
    SnapSettings s = snap_settings(o, band, index.size(), {previous_noise, previous_height_noise},
                                   h, h_final, refine);
    s.cut_zone = &cut_zone;
    return s;
  };
  // A pass on some bricks (settings.only), then the redistance (the front moved by up to a voxel).
  auto pass_on_bricks = [&](const SnapSettings& settings) {
    const auto t_fit = Clock::now();
    const SnapPass snapped = snap_to_fits(band, index, settings, coarse, coarse_curvature, o.progress);
    stage.refused_flips += snapped.refused;
    stage.fit_voxels += snapped.voxels;
    stage.fit_models += snapped.models;
    stage.facing_fits += snapped.facing_fits;
    stage.seconds_fit += seconds_since(t_fit);
    const auto t_redistance = Clock::now();
    band = redistanced_near(band, *settings.only, W, 1.0, o.progress);
    stage.seconds_redistance += seconds_since(t_redistance);
  };
  for (int pass = 0; !carved_bricks.empty() && pass < kPassesAfterCarving; ++pass) {
    SnapSettings settings = settings_for(false);
    settings.only = &carved_bricks;
    pass_on_bricks(settings);
  }
  // On the final level, clean data get clean_final_passes (the first pass's noise
  // estimate decides).
  int passes = o.snap_passes;
  bool refine = false;  // after a clean pass: the front is within ~0.1 voxel of the fits
  int unredistanced = 0;  // passes since the last redistance
  // A level's first pass may run before any level has read the points' noise (the coarse
  // flow reads none): where that pass's noise asks for kRestartGrowth times its height fits'
  // points or more, the final level, and a level whose fits read more noise than
  // kReferenceNoise final voxels, start again from the band before it. Without the restart
  // the few-point fits' noise stayed in the band: each later pass moves a voxel by the mean
  // offset of its neighbourhood, which keeps the band's own high-frequency part, ~0.6 sigma
  // of 16-point fits (200k points, 0.1 %: bear 1.59 -> 1.44e-4 of the diagonal, truth to
  // surface; 20k points, 0.5 %, on the middle level: blobby, knot -9 %). A middle level
  // under milder noise leaves the final level little to undo (20k points, 0.1 %: 20 % more
  // time for about 1 %).
  bool restarted = false;
  NarrowBand before_first;
  SnapPass last_pass;
  for (int pass = 0; pass < passes; ++pass) {
    const auto t_fit = Clock::now();
    // (Only a pass whose fits could still grow by kRestartGrowth can restart.)
    if (pass == 0 && !restarted && kRestartGrowth * settings_for(refine).height_neighbors <= 256) before_first = band;
    SnapSettings settings = settings_for(refine);
    if (level == levels - 1 && o.refit_moved) settings.moved_limit = kRefitChange;
    if (pass > 0 && o.widen_smooth && settings.soft_scales && !last_pass.smooth.empty()) {
      settings.widen = &last_pass.smooth;
      settings.widened_neighbors = std::min(256, int(std::lround(kWidenGrowth * settings.height_neighbors)));
      stage.widened_bricks += last_pass.smooth.size();
    }
    const SnapPass snapped = snap_to_fits(band, index, settings, coarse, coarse_curvature, o.progress);
    last_pass = snapped;
    previous_noise = snapped.noise * h / h_final;
    previous_height_noise = snapped.height_noise * h / h_final;
    if (pass == 0 && !restarted && before_first.active_voxel_count() > 0 && (level == levels - 1 || previous_height_noise > kReferenceNoise) &&
        settings_for(false).height_neighbors >= kRestartGrowth * settings.height_neighbors) {
      band = std::move(before_first);
      restarted = true;
      pass = -1;
      stage.seconds_fit += seconds_since(t_fit);
      continue;
    }
    stage.height_neighbors = settings.height_neighbors;
    if (pass == 0 && level == levels - 1 && snapped.clean) passes = std::max(passes, o.clean_final_passes);
    refine = snapped.clean;
    stage.second_order = snapped.clean;
    stage.height_fits += snapped.height_fits;
    stage.refused_flips += snapped.refused;
    stage.seconds_fit += seconds_since(t_fit);
    stage.fit_voxels += snapped.voxels;
    stage.fit_models += snapped.models;
    stage.facing_fits += snapped.facing_fits;
    stage.last_change = snapped.mean_change;
    stage.noise = snapped.noise;
    stage.height_noise = snapped.height_noise;
    stage.smoothing = snapped.smoothing;
    ++stage.steps;
    // The snap moved the front by up to one voxel, so voxels up to W + 1 voxels from the
    // old front may now lie within W of the new one: the domain grows by one voxel per
    // pass since the last redistance (redistance dilates by W - W_in; one 26-neighbour
    // step reaches one voxel further from any front). Without it the band misses voxels
    // near the front where the front moved outward, and the next level's upsampling or
    // the marching cubes (which skip cells with an inactive corner) leave holes. A clean
    // pass followed by a refining one skips it: the refining pass reads |u| < 2 voxels,
    // which the snap kept a distance up to the fits' change (measured: the same Chamfer,
    // 0.18 s less on bench_reconstruct's bunny at 20k).
    ++unredistanced;
    const bool last = pass + 1 == passes || stage.last_change < o.tolerance;
    if (last || !snapped.clean || double(unredistanced) + 1.0 >= W) {  // the domain may grow W - 1 voxels at most
      const auto t_redistance = Clock::now();
      band = redistanced(band, W, double(unredistanced), o.progress);
      unredistanced = 0;
      stage.seconds_redistance += seconds_since(t_redistance);
    }
    o.progress.step((double(level) + double(pass + 1) / passes) / levels, "reconstruct");
    if (last) break;
  }
  // Noisy data, final level: where the last pass moved the front far, one more pass on those
  // bricks (refit_moved, kRefitChange).
  if (level == levels - 1 && !last_pass.clean && !last_pass.moved.empty() && previous_height_noise <= kReferenceNoise) {
    SnapSettings settings = settings_for(false);
    settings.only = &last_pass.moved;
    settings.fixed_sigma = last_pass.noise;
    settings.fixed_residual = last_pass.height_noise * h;
    pass_on_bricks(settings);
    stage.refit_bricks = last_pass.moved.size();
  }
  if (level > 0) stage.converged = stage.last_change < o.tolerance;
  return {std::move(band), std::move(stage), {previous_noise, previous_height_noise}};
}

}  // namespace levelset::apps::detail
