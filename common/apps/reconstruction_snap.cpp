// reconstruct_surface's finer levels: the snap of the front onto the points' local fits
// (reconstruction_parts.hpp).
#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "apps/nearby_points.hpp"
#include "apps/reconstruction_parts.hpp"
#include "distance/redistance.hpp"
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

// Snap: voxels within this many voxels of the front take their fit's offset (the marching
// cubes read |u| < 1 h; the margin covers the front's move).
constexpr double kSnapWindow = 1.5;
// Later passes after a clean one: the front moved by ~0.01-0.1 voxel, so only the voxels the
// redistance keeps (interface voxels, |u| < h) and the marching cubes read need a new fit
// (same Chamfer on bench_reconstruct as 1.5, a third fewer fits).
constexpr double kRefineWindow = 1.0;
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
// Second-order snap fits (point_distance.hpp sheet_fit): at least this many points per height
// fit (a quadric has 6 unknowns; on bench_reconstruct's clean cases 12-16 measured best, 30+
// worse: the quadric no longer describes the larger patch), used where they agree with the
// plane fit within kHeightGuard voxels, or kHeightGuardNoise times the noise the previous
// pass measured (height fits' residual) where that is more: the two fits' offsets differ by
// their noise as well, and under 0.5 % noise (1.5-1.7 final voxels) a one-voxel guard sent a
// third of the voxels back to the plane fit, over `neighbors` (8) points against the height
// fit's 60-100: a noisy sphere's RMS error 0.35 -> 0.30 sigma; bench_reconstruct --sweep, 20k
// points, 0.5 % noise: median ratio to Poisson's Chamfer 0.979 -> 0.919.
constexpr int kHeightNeighbors = 16;
constexpr double kHeightGuard = 1.0;
constexpr double kHeightGuardNoise = 2.0;
// Data are "clean" when the fits' mean noise estimate is below this many final voxels: then
// the snap takes the height fits' offsets averaged over the voxel and its 6 face neighbours
// only (unbiased fits: the 3x3x3 averaging blurred them, costing bench_reconstruct's clean
// cases a factor 1.5-2.5 in Chamfer; no averaging at all was as accurate but its second
// pass gave the bunny with 20k points 7 handles); otherwise the plane fits, 3x3x3-averaged
// and smoothed (the quadric's variance under noise made the noisy cases 10-40% worse).
// Measured: clean 0.04-0.17 voxels, 0.2% noise 0.6-0.8.
constexpr double kCleanNoise = 0.4;
constexpr long kMaxSmoothing = 3;
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
constexpr double kWidenWeight = 0.4;
constexpr double kWidenGrowth = 5.0 / 3.0;
// The noise (final voxels) at which kNoisyHeightNeighbors was measured best (0.2% noise).
constexpr double kReferenceNoise = 0.7;
// The height fits' residual on clean points (the quadric's third-order misfit, float
// positions): 0.01-0.03 final voxels measured; residuals are counted as noise beyond it.
constexpr double kResidualFloor = 0.1;
// The redone noise correction's change is at most this many of the pass's own noise sigmas
// (as the fit's own bound, point_distance.cpp).
constexpr double kMaxNoiseShiftRedo = 0.5;
// Voxels within this many voxels of the front compute fits on a first pass; the others in the
// snap window take their neighbours' mean offset (the offset is nearly constant along the
// normal; bench_reconstruct: the same Chamfer as fits on the whole window, 15% faster).
constexpr double kFitWindow = 1.0;
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
  std::vector<std::uint64_t> moved;  // brick_key (sorted) of the bricks whose voxels moved more than settings.moved_limit on average
  // brick_key (sorted) of the bricks whose soft-scale height fits kept their largest patch
  // with a mean weight of at least kWidenWeight (soft_scales passes only).
  std::vector<std::uint64_t> smooth;
};

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
};

// One snap pass (see the header): every voxel with |u| < window h takes the signed offset s
// of its local fit along the level set's normal, moved by at most one voxel. Per-brick sums
// added in brick order (deterministic).
SnapPass snap_to_fits(NarrowBand& band, const PointIndex& index, const SnapSettings& settings, const NarrowBand& coarse,
                      const std::vector<float>& coarse_curvature, const ProgressHook& progress) {
  const double h = band.voxel_size();
  const double window = settings.window, fit_window = std::min(settings.fit_window, settings.window);
  const int neighbors = settings.neighbors;
  const bool same_grid = coarse.voxel_size() == h;  // a single level: its own curvature
  const float unset = std::numeric_limits<float>::quiet_NaN();
  const FitSettings fit_settings = snap_fit_settings(neighbors, settings.height_neighbors, kOneSidedBand * h, h,
                                                     {settings.noise, settings.noisy_height, settings.soft_scales},
                                                     settings.wide_blocks);
  FitSettings widened_settings = fit_settings;
  widened_settings.height_neighbors = std::max(settings.height_neighbors, settings.widened_neighbors);
  // 1. The front offset e = clamp(s - u, +-h) of every voxel within the window.
  std::vector<float> offset(band.active_voxel_count(), unset);
  std::vector<std::uint8_t> moves(band.active_voxel_count(), 0);  // within the window
  std::vector<float> height_offset(band.active_voxel_count(), unset);  // the height fit's, or the plane's
  std::vector<double> spread(band.brick_count(), 0.0);  // per brick: sum of the fits' spread
  std::vector<std::uint32_t> fitted(band.brick_count(), 0);
  std::vector<std::uint32_t> heights(band.brick_count(), 0);
  std::vector<std::uint32_t> models(band.brick_count(), 0);
  std::vector<double> residual(band.brick_count(), 0.0);  // per brick: sum of the height fits' residuals
  std::vector<double> large_weight(band.brick_count(), 0.0);  // per brick: sum of the height fits' large_weight
  // Noisy data: each height fit's offset from the front before the clamp, and its noise gain
  // (SheetFit::noise_gain), to redo the noise correction with this pass's own noise below.
  std::vector<float> raw_second, gain;
  if (settings.noisy_height) {
    raw_second.assign(band.active_voxel_count(), unset);
    gain.assign(band.active_voxel_count(), 0.0f);
  }
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
                        }
                      }
                    });
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
  for (int smooth = 0; smooth < smoothing; ++smooth) {
    std::vector<float> smoothed(offset.size(), unset);
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
    offset.swap(smoothed);
  }
  std::vector<float> next(band.values().begin(), band.values().end());
  std::vector<double> change(band.brick_count(), 0.0);
  std::vector<std::uint32_t> count(band.brick_count(), 0);
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
  std::uint64_t refused = 0;
  if (settings.guard) {
    TopologyGuardOptions guard;
    guard.eps = 1e-3 * h;
    guard.progress = progress;
    TopologyGuardResult kept = guard_topology(band, band, std::move(next), guard);
    next = std::move(kept.values);
    refused = kept.refused_flips;
  }
  band.swap_values(next);
  SnapPass pass;
  pass.refused = refused;
  pass.noise = sigma;
  pass.height_noise = height_n > 0 ? residual_sum / double(height_n) / h : 0.0;
  pass.smoothing = smoothing;
  pass.clean = clean;
  pass.height_fits = height_n;
  for (const std::uint32_t m : models) pass.models += m;
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

}  // namespace

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
  std::vector<std::uint64_t> carved_bricks;
  if (level > 0 && o.carve_gaps) {
    CarveOutput carved = carve_buried_gaps(std::move(band), index, where.carve, o.progress);
    band = std::move(carved.band);
    stage.buried_points = carved.buried;
    stage.carved_regions = carved.regions;
    stage.pierced_regions = carved.pierced_regions;
    stage.webs_cut = carved.webs;
    stage.web_tunnels = carved.web_tunnels;
    stage.carved_voxels = carved.carved_voxels;
    carved_bricks = std::move(carved.bricks);
  }
  stage.seconds_start += seconds_since(t_up);
  auto settings_for = [&](bool refine) {
    return snap_settings(o, band, index.size(), {previous_noise, previous_height_noise}, h, h_final, refine);
  };
  // A pass on some bricks (settings.only), then the redistance (the front moved by up to a voxel).
  auto pass_on_bricks = [&](const SnapSettings& settings) {
    const auto t_fit = Clock::now();
    const SnapPass snapped = snap_to_fits(band, index, settings, coarse, coarse_curvature, o.progress);
    stage.refused_flips += snapped.refused;
    stage.fit_voxels += snapped.voxels;
    stage.fit_models += snapped.models;
    stage.seconds_fit += seconds_since(t_fit);
    const auto t_redistance = Clock::now();
    band = redistanced(band, W, 1.0, o.progress);
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
