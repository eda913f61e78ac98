#include "apps/reconstruction.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <deque>
#include <limits>
#include <optional>
#include <string>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "apps/point_distance.hpp"
#include "apps/point_sampling.hpp"
#include "core/error.hpp"
#include "distance/redistance.hpp"
#include "evolve/evolution.hpp"
#include "grid/band_accessor.hpp"
#include "grid/band_builder.hpp"
#include "grid/build_from_sdf.hpp"
#include "grid/for_each_active_parallel.hpp"
#include "grid/sign_components.hpp"
#include "grid/topology_guard.hpp"
#include "surface/marching_cubes.hpp"

namespace levelset::apps {

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

using Clock = std::chrono::steady_clock;

// The coarsest level's attraction: beta = -clamp(gain * offset / h): a front within
// 1 / gain voxels of its target moves a fraction 0.5 gain / (1 + 6 w) of the way per step
// (forward Euler at cfl 0.5 with the curvature's explicit limit); 3 converges in a few
// steps without overshoot for w >= 0.1.
constexpr double kAttractionGain = 3.0;
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
// plane fit within kHeightGuard voxels.
constexpr int kHeightNeighbors = 16;
constexpr double kHeightGuard = 1.0;
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
// ~ sigma^2 / (density r^2) goes as density^(-1/8), so the count density r^2 as density^(3/4)),
// with one smoothing pass at most. bench_reconstruct, noisy cases: 48 points best at 20k
// (Chamfer -11% against the plane fits), 160 at 100k (-8%); the scaling law gives 3.3 for a
// 5x density, as measured.
constexpr int kNoisyHeightNeighbors = 48;
constexpr double kReferenceDensity = 0.15;
constexpr double kDensityExponent = 0.75;
// The noise (final voxels) at which kNoisyHeightNeighbors was measured best (0.2% noise).
constexpr double kReferenceNoise = 0.7;
// The height fits' residual on clean points (the quadric's third-order misfit, float
// positions): 0.01-0.03 final voxels measured; residuals are counted as noise beyond it.
constexpr double kResidualFloor = 0.1;
// Voxels within this many voxels of the front compute fits on a first pass; the others in the
// snap window take their neighbours' mean offset (the offset is nearly constant along the
// normal; bench_reconstruct: the same Chamfer as fits on the whole window, 15% faster).
constexpr double kFitWindow = 1.0;
// A component whose front voxels have a point within 1.5 coarse voxels for less than this
// fraction of them is a stray (drop_unsupported_components).
constexpr double kMinSupport = 0.5;
constexpr double kSupportDistance = 1.5;
constexpr double kGapClosing = 1.5;

// The resolution when the caller gives none (see the header): voxels kSpacingVoxels sample
// spacings wide, widened to kNoiseVoxels times the noise estimate, within [kAutoMin, kAutoMax].
// Measured on the built-in knot (20k points, resolutions 128-512): clean points gain from
// every finer grid (512: 3x better Chamfer than 256), noisy ones (0.2%) are best near 2 sigma
// per voxel (finer grids fit the noise).
constexpr double kSpacingVoxels = 0.25, kNoiseVoxels = 2.0;
constexpr int kAutoMin = 64, kAutoMax = 512;
// Levels from the data (see reconstruct_surface): a single level runs the flow on the final
// grid (slow: 15-30 s at 256); more than three coarsen beyond what 20k points need.
constexpr int kMinAutoLevels = 2, kMaxAutoLevels = 3;

int auto_resolution(const SamplingEstimate& s, double longest, double half_width) {
  const double h = std::max(kSpacingVoxels * s.spacing, kNoiseVoxels * s.noise);
  const double pad = 2.0 * (half_width + 2.0);
  if (!(h > 0.0)) return kAutoMax;
  return int(std::clamp(std::ceil(longest / h + pad), double(kAutoMin), double(kAutoMax)));
}

double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

void require(bool ok, const std::string& reason) {
  if (!ok) throw Error(ErrorCode::InvalidArgument, "reconstruct", reason);
}

void validate(const std::vector<Vec3d>& points, const ReconstructionOptions& o) {
  for (std::size_t i = 0; i < points.size(); ++i)
    if (!std::isfinite(points[i].x) || !std::isfinite(points[i].y) || !std::isfinite(points[i].z))
      throw Error(ErrorCode::NonFinite, "reconstruct", "point " + std::to_string(i) + " is not finite");
  require(points.size() >= 4, "need at least 4 points, got " + std::to_string(points.size()));
  if (!std::isfinite(o.voxel_size) || !std::isfinite(o.half_width) || !std::isfinite(o.shell_offset) ||
      !std::isfinite(o.curvature_weight) || !std::isfinite(o.tolerance))
    throw Error(ErrorCode::NonFinite, "reconstruct", "non-finite option");
  require(!(o.resolution > 0 && o.voxel_size > 0.0), "give at most one of resolution and voxel_size");
  require(o.resolution >= 0 && o.voxel_size >= 0.0, "resolution and voxel_size must not be negative");
  require(o.half_width >= 2.0 && o.half_width <= 8.0, "half_width must be in [2, 8] voxels");
  require(o.resolution == 0 || o.resolution >= int(2 * (o.half_width + 2)) + 8,
          "resolution " + std::to_string(o.resolution) + " is too small for the band");
  require(o.levels >= 0 && o.levels <= 6, "levels must be in [1, 6] (0: from the data)");
  require(o.shell_offset >= 1.0 && o.shell_offset <= 16.0, "shell_offset must be in [1, 16] voxels");
  require(o.neighbors >= 1 && o.neighbors <= 256, "neighbors must be in [1, 256]");
  require(o.curvature_weight >= 0.0, "curvature_weight must be >= 0");
  require(o.max_steps >= 1, "max_steps must be >= 1");
  require(o.snap_passes >= 0 && o.snap_passes <= 16, "snap_passes must be in [0, 16]");
  require(o.clean_final_passes >= 0 && o.clean_final_passes <= 16, "clean_final_passes must be in [0, 16]");
  require(o.tolerance > 0.0, "tolerance must be > 0");
  require(o.max_resolution >= 16, "max_resolution must be >= 16");
  if (!std::isfinite(o.free_distance)) throw Error(ErrorCode::NonFinite, "reconstruct", "non-finite free_distance");
  require(o.free_distance >= 0.0, "free_distance must be >= 0 coarse voxels");
}

// The band with its frame moved by `offset` and its half-width set to `half_width` voxels
// (values, active voxels and signs unchanged).
NarrowBand reframed(const NarrowBand& band, const Vec3d& offset, double half_width) {
  GridFrame frame = band.frame();
  frame.origin = frame.origin + offset;
  frame.half_width = half_width;
  std::vector<BrickRecord> records(band.brick_count());
  for (std::uint32_t b = 0; b < band.brick_count(); ++b)
    records[b] = {band.bricks()[b].coord, band.bricks()[b].active, band.inside_mask(b)};
  std::vector<float> values(band.values().begin(), band.values().end());
  return NarrowBand::assemble(frame, std::move(records), std::move(values), band.far_inside());
}

// Start band on the coarsest level: the outer component of {d < offset} (see the header).
NarrowBand start_shell(const PointIndex& index, const BBox& box, const Vec3d& origin, double h, double offset,
                       double half_width, const ProgressHook& progress) {
  const Vec3d far = (box.max - origin) / h;
  const long nx = long(std::ceil(far.x + offset + half_width + 3)), ny = long(std::ceil(far.y + offset + half_width + 3)),
             nz = long(std::ceil(far.z + offset + half_width + 3));
  if (double(nx) * double(ny) * double(nz) > double(1u << 27))
    throw Error(ErrorCode::LimitExceeded, "reconstruct",
                "the coarsest level's start grid exceeds 2^27 voxels: use more levels or a coarser resolution");
  const std::size_t total = std::size_t(nx * ny * nz);
  auto at = [&](long i, long j, long k) { return std::size_t((k * ny + j) * nx + i); };
  std::vector<float> dist(total);
  tbb::parallel_for(tbb::blocked_range<long>(0, nz), [&](const tbb::blocked_range<long>& r) {
    for (long k = r.begin(); k != r.end(); ++k) {
      progress.check("reconstruct start");
      for (long j = 0; j < ny; ++j)
        for (long i = 0; i < nx; ++i)
          dist[at(i, j, k)] = float(index.nearest(origin + Vec3d{double(i), double(j), double(k)} * h).distance / h);
    }
  });
  // Flood fill of the outside from the grid's faces (they lie beyond the shell by construction).
  std::vector<std::uint8_t> outside(total, 0);
  std::deque<std::size_t> queue;
  auto seed = [&](long i, long j, long k) {
    const std::size_t n = at(i, j, k);
    if (!outside[n] && dist[n] > offset) {
      outside[n] = 1;
      queue.push_back(n);
    }
  };
  for (long k = 0; k < nz; ++k)
    for (long j = 0; j < ny; ++j)
      for (long i = 0; i < nx; ++i)
        if (i == 0 || j == 0 || k == 0 || i == nx - 1 || j == ny - 1 || k == nz - 1) seed(i, j, k);
  while (!queue.empty()) {
    const std::size_t n = queue.front();
    queue.pop_front();
    const long i = long(n % std::size_t(nx)), j = long((n / std::size_t(nx)) % std::size_t(ny)),
               k = long(n / std::size_t(nx * ny));
    if (i > 0) seed(i - 1, j, k);
    if (i < nx - 1) seed(i + 1, j, k);
    if (j > 0) seed(i, j - 1, k);
    if (j < ny - 1) seed(i, j + 1, k);
    if (k > 0) seed(i, j, k - 1);
    if (k < nz - 1) seed(i, j, k + 1);
  }
  progress.check("reconstruct start");
  // Signed value in world units: d - offset outside and in the shell; inside the cavity a
  // negative value no larger than the distance to the outer shell (d - offset is 1-Lipschitz).
  auto sdf = [&](const Vec3d& p) {
    const Vec3d q = (p - origin) / h;
    const long i = std::clamp(long(std::lround(q.x)), 0L, nx - 1), j = std::clamp(long(std::lround(q.y)), 0L, ny - 1),
               k = std::clamp(long(std::lround(q.z)), 0L, nz - 1);
    const std::size_t n = at(i, j, k);
    const double v = double(dist[n]) - offset;
    if (outside[n]) return v * h;
    return (v < 0.0 ? v : -v - 1e-3) * h;
  };
  SdfBuildOptions build;
  build.frame = GridFrame{h, origin, half_width};
  build.progress = progress;
  BBox bounds = box;
  const Vec3d pad{(offset + 1) * h, (offset + 1) * h, (offset + 1) * h};
  bounds.min = bounds.min - pad;
  bounds.max = bounds.max + pad;
  const NarrowBand raw = build_from_sdf(sdf, bounds, build).band;
  RedistanceOptions redo;
  redo.progress = progress;
  return redistance(raw, redo).band;
}

// A per-voxel field of `coarse` (band value order) at voxel c of the grid with half its
// voxel size and the same origin: the trilinear interpolant at c / 2, the mean of the 1, 2, 4
// or 8 coarse voxels around it. NaN when one of them is not active.
double coarse_field_at(BandAccessor& acc, const NarrowBand& coarse, const std::vector<float>& field, const Coord& c) {
  const int lx = c.x >> 1, ly = c.y >> 1, lz = c.z >> 1;
  const int hx = lx + (c.x & 1), hy = ly + (c.y & 1), hz = lz + (c.z & 1);
  double sum = 0.0;
  int n = 0;
  for (int z = lz; z <= hz; ++z)
    for (int y = ly; y <= hy; ++y)
      for (int x = lx; x <= hx; ++x) {
        const Coord q{x, y, z};
        const std::uint32_t b = acc.locate(brick_of(q));
        if (b == kNoBrick) return std::nan("");
        const Brick& br = coarse.bricks()[b];
        const int i = local_index(q);
        if (!br.active.test(i)) return std::nan("");
        sum += double(field[br.value_offset + br.slot(i)]);
        ++n;
      }
  return sum / n;
}

// A per-voxel field of `band` at its voxel c; NaN when c is not active.
double field_at(BandAccessor& acc, const NarrowBand& band, const std::vector<float>& field, const Coord& c) {
  const std::uint32_t b = acc.locate(brick_of(c));
  if (b == kNoBrick) return std::nan("");
  const Brick& br = band.bricks()[b];
  const int i = local_index(c);
  return br.active.test(i) ? double(field[br.value_offset + br.slot(i)]) : std::nan("");
}

// The band resampled (trilinear) at half its voxel size, same origin: the fine voxels whose
// 1-8 coarse neighbours are active and whose value is within W h; the others take the sign
// of the coarse voxel they lie in. Every coarse brick gives its 8 fine bricks (TBB over
// coarse bricks, assembled in key order: deterministic). No redistance: the snap that
// follows rewrites the values near the front and redistances.
NarrowBand upsample(const NarrowBand& coarse, double half_width, const ProgressHook& progress) {
  const double h = 0.5 * coarse.voxel_size();
  const double limit = half_width * h;
  // A fine voxel's value differs from that of the coarse voxel c / 2 it touches by at most
  // one coarse voxel (1-Lipschitz): beyond limit + h_c it is not in the band.
  const double far = limit + coarse.voxel_size();
  const std::vector<float> values(coarse.values().begin(), coarse.values().end());
  BandBuilder builder(GridFrame{h, coarse.origin(), half_width});
  tbb::parallel_for(tbb::blocked_range<std::uint32_t>(0, std::uint32_t(coarse.brick_count()), 4),
                    [&](const tbb::blocked_range<std::uint32_t>& r) {
                      progress.check("reconstruct upsample");
                      BandAccessor acc(coarse);
                      std::vector<float> dense(512);
                      for (std::uint32_t cb = r.begin(); cb != r.end(); ++cb) {
                        const Coord cbc = coarse.bricks()[cb].coord;
                        for (int sub = 0; sub < 8; ++sub) {
                          const Coord fb{2 * cbc.x + (sub & 1), 2 * cbc.y + ((sub >> 1) & 1), 2 * cbc.z + ((sub >> 2) & 1)};
                          const Coord o = brick_origin(fb);
                          BrickMask active{}, inside{};
                          for (int n = 0; n < 512; ++n) {
                            const Coord c = o + local_coord(n);
                            const Coord parent{c.x >> 1, c.y >> 1, c.z >> 1};
                            const std::optional<float> near = acc.probe(parent);
                            bool in = near ? *near < 0.0f : acc.is_inside(parent);
                            if (near && std::abs(double(*near)) <= far) {
                              const double v = coarse_field_at(acc, coarse, values, c);
                              if (std::isfinite(v)) {
                                in = v < 0.0;
                                if (std::abs(v) <= limit) {
                                  active.set(n);
                                  dense[std::size_t(n)] = float(v);
                                }
                              }
                            }
                            if (in) inside.set(n);
                          }
                          builder.add_brick(fb, active, inside, dense.data());
                        }
                      }
                    });
  return builder.finish(coarse.far_inside());
}

// Mean front motion of the coarsest level's flow: the speed function adds |beta| of the
// voxels within one voxel of the front (fixed point, so the sum is the same in any order:
// deterministic for any thread count); stop_when turns it into voxels per step.
struct MotionMeter {
  static constexpr double kScale = 1048576.0;
  std::atomic<std::uint64_t> sum{0};
  std::atomic<std::uint64_t> count{0};
  double take_mean() {
    const std::uint64_t n = count.exchange(0);
    const std::uint64_t s = sum.exchange(0);
    return n > 0 ? double(s) / kScale / double(n) : 0.0;
  }
};

// The coarsest level's speed (see the header), reading the cached fits (on the fly off the
// cache).
evolve::SpeedFunction fit_speed(const NarrowBand& cache, const std::vector<LocalFit>& fits, const PointIndex& index,
                                int neighbors, double weight, MotionMeter& meter) {
  const double h = cache.voxel_size();
  const Vec3d origin = cache.origin();
  evolve::SpeedFunction s;
  s.name = "point-attraction";
  s.needs = evolve::kNeedsPosition | evolve::kNeedsNormal | evolve::kNeedsMean;
  s.has_advective = true;
  s.has_parabolic = weight > 0.0;
  s.diffusion = weight * h;
  s.eval = [&cache, &fits, &index, &meter, neighbors, weight, h, origin](const evolve::SpeedBatch& b,
                                                                           const evolve::SpeedOutput& out) {
    BandAccessor acc(cache);
    std::uint64_t sum = 0, count = 0;
    for (int i = 0; i < b.count; ++i) {
      const Coord c{int(std::lround((double(b.x[i]) - origin.x) / h)), int(std::lround((double(b.y[i]) - origin.y) / h)),
                    int(std::lround((double(b.z[i]) - origin.z) / h))};
      const std::uint32_t br = acc.locate(brick_of(c));
      LocalFit fit;
      const int n = local_index(c);
      if (br != kNoBrick && cache.bricks()[br].active.test(n)) {
        const Brick& brick = cache.bricks()[br];
        fit = fits[brick.value_offset + brick.slot(n)];
      } else {
        fit = local_fit(index, cache.world(c), neighbors);
      }
      const Vec3d nrm{double(b.nx[i]), double(b.ny[i]), double(b.nz[i])};
      const double H = std::clamp(double(b.mean[i]), -1.0 / h, 1.0 / h);
      const double u = double(b.d[i]);
      // No curvature correction here: with the evolving front's own H it is a backward heat
      // term (+ (g rho^2 / 4 h) H in beta, rho^2 the fit's tangential spread, larger than the
      // w d H smoothing for k >~ 12), which grew wrinkles and spurious handles and kept the
      // flow from converging (knot, 20k points, k = 24: genus 2-8 after 120 steps; without
      // it genus 1 in 20 steps). The snaps apply it with the coarse level's fixed H.
      const double front_offset = fit.signed_offset(nrm, H, 0.0) - u;
      const double advective = -std::clamp(kAttractionGain * front_offset / h, -1.0, 1.0);
      const double parabolic = -weight * std::min(double(fit.d), h) * H;
      out.advective[i] = float(advective);
      out.parabolic[i] = float(parabolic);
      if (std::abs(u) < h) {
        sum += std::uint64_t(std::lround(std::min(std::abs(advective + parabolic), 4.0) * MotionMeter::kScale));
        ++count;
      }
    }
    meter.sum.fetch_add(sum, std::memory_order_relaxed);
    meter.count.fetch_add(count, std::memory_order_relaxed);
  };
  return s;
}

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

// Components the data do not support: a component of the inside or outside voxel set
// (not the exterior, not the inside component with the largest front) whose front voxels have a point
// within `support` for less than kMinSupport of them. They arise on the coarse level where
// the front crossed a gap between parts far from the data (the free_distance rule lets the
// topology change there), and the guard keeps them once they reach the data (measured: the
// knot at R = 128 with 0.2% noise kept a blob 2 coarse voxels off the surface, 5% of its
// front near a point). Each is turned to the other sign; the caller redistances. Components
// with voxels off the band are kept (too large to be strays). Returns how many were turned.
std::uint64_t drop_unsupported_components(NarrowBand& band, const PointIndex& index, double support,
                                          const ProgressHook& progress) {
  SignComponentsOptions sco;
  sco.progress = progress;
  sco.inside_connectivity = 6;  // a piece joined by an edge or a corner only may be drawn apart
  const SignComponentsResult comps = sign_components(band, sco);
  std::size_t largest = comps.components.size();  // the inside component with the largest front
  for (std::size_t c = 0; c < comps.components.size(); ++c)
    if (comps.components[c].inside &&
        (largest == comps.components.size() || comps.components[c].front.size() > comps.components[largest].front.size()))
      largest = c;
  std::vector<std::uint8_t> drop(comps.components.size(), 0);
  std::uint64_t dropped = 0;
  for (std::size_t c = 0; c < comps.components.size(); ++c) {
    const SignComponent& comp = comps.components[c];
    if (c == largest || comp.touches_box || !comp.all_active || comp.front.empty()) continue;
    std::size_t near = 0;
    for (const Coord& f : comp.front)
      if (index.nearest(band.world(f)).distance <= support) ++near;
    if (double(near) < kMinSupport * double(comp.front.size())) {
      drop[c] = 1;
      ++dropped;
    }
  }
  if (dropped == 0) return 0;
  std::vector<float> values(band.values().begin(), band.values().end());
  const float eps = float(1e-3 * band.voxel_size());
  for (std::uint32_t b = 0; b < band.brick_count(); ++b) {
    std::size_t slot = band.bricks()[b].value_offset;
    band.for_each_active_in_brick(b, [&](const Coord& c, float v) {
      const std::size_t i = slot++;
      if (!drop[std::size_t(comps.label[comps.index_of(c)])]) return;
      values[i] = v < 0.0f ? std::max(-v, eps) : std::min(-v, -eps);
    });
  }
  band.swap_values(values);
  return dropped;
}

struct SnapPass {
  double mean_change = 0.0;     // voxels, over the snapped voxels
  double noise = 0.0;           // mean robust spread of the fits, voxels
  double height_noise = 0.0;    // mean residual of the height fits (noise without sagitta), voxels
  int smoothing = 0;            // extra smoothing passes of the offsets
  bool clean = false;           // the height fits' offsets were used, unaveraged
  std::uint64_t voxels = 0;     // snapped (fits computed)
  std::uint64_t height_fits = 0;  // of them with a usable height fit
  std::uint64_t refused = 0;    // sign changes refused (not simple: they would change the topology)
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
// kHeightNeighbors (clean data: 16 measured best; 24 cost the clean blobby 20 %).
int height_neighbors_for(double density, double noise) {
  if (!(density > 0.0)) return kNoisyHeightNeighbors;
  const double excess = std::sqrt(std::max(0.0, noise * noise - kResidualFloor * kResidualFloor));
  const double k = kNoisyHeightNeighbors * std::pow(density / kReferenceDensity, kDensityExponent) *
                   std::sqrt(excess / kReferenceNoise);
  return int(std::clamp(std::lround(k), long(kHeightNeighbors), 256L));
}

int noisy_height_neighbors(const NarrowBand& band, std::size_t points, double h_final) {
  const double density = front_density(band, points, h_final);
  if (!(density > 0.0)) return kNoisyHeightNeighbors;
  const double k = kNoisyHeightNeighbors * std::pow(density / kReferenceDensity, kDensityExponent);
  return int(std::clamp(std::lround(k), long(kNoisyHeightNeighbors) / 2, 256L));
}

struct SnapSettings {
  int neighbors = 8;             // plane fits
  int height_neighbors = kHeightNeighbors;  // height fits
  bool noisy_height = false;     // noisy data: the height fits' offsets as well (see kNoisyHeightNeighbors)
  double window = kSnapWindow;   // voxels that move
  double fit_window = kFitWindow;  // voxels with their own fit (within the window)
  double h_final = 0.0;
  bool guard = true;             // keep the topology
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
  // 1. The front offset e = clamp(s - u, +-h) of every voxel within the window.
  std::vector<float> offset(band.active_voxel_count(), unset);
  std::vector<std::uint8_t> moves(band.active_voxel_count(), 0);  // within the window
  std::vector<float> height_offset(band.active_voxel_count(), unset);  // the height fit's, or the plane's
  std::vector<double> spread(band.brick_count(), 0.0);  // per brick: sum of the fits' spread
  std::vector<std::uint32_t> fitted(band.brick_count(), 0);
  std::vector<std::uint32_t> heights(band.brick_count(), 0);
  std::vector<double> residual(band.brick_count(), 0.0);  // per brick: sum of the height fits' residuals
  tbb::parallel_for(tbb::blocked_range<std::uint32_t>(0, std::uint32_t(band.brick_count()), 8),
                    [&](const tbb::blocked_range<std::uint32_t>& r) {
                      progress.check("reconstruct snap");
                      BandAccessor acc(band), coarse_acc(coarse);
                      for (std::uint32_t b = r.begin(); b != r.end(); ++b) {
                        std::size_t slot = band.bricks()[b].value_offset;
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
                          const SheetFit sf = sheet_fit(index, band.world(c), g / gl, neighbors,
                                                        settings.height_neighbors, kOneSidedBand * h);
                          const LocalFit& fit = sf.plane;
                          const double plane = fit.signed_offset(g / gl, H, kMaxCorrection * h);
                          double second = plane;
                          if (sf.has_height && std::abs(sf.height_offset - plane) <= kHeightGuard * h) {
                            second = sf.height_offset;
                            residual[b] += sf.height_residual;
                            ++heights[b];
                          }
                          offset[i] = float(std::clamp(plane - u, -h, h));
                          height_offset[i] = float(std::clamp(second - u, -h, h));
                          spread[b] += double(fit.spread);
                          ++fitted[b];
                        });
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
  const double sigma = sigma_n > 0 ? sigma_sum / double(sigma_n) / h : 0.0;
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
  for (std::size_t b = 0; b < change.size(); ++b) {
    pass.mean_change += change[b];
    pass.voxels += count[b];
  }
  if (pass.voxels > 0) pass.mean_change /= double(pass.voxels);
  return pass;
}

}  // namespace

ReconstructionResult reconstruct_surface(const std::vector<Vec3d>& input, const ReconstructionOptions& o) {
  const auto t_start = Clock::now();
  validate(input, o);
  BBox box;
  for (const Vec3d& p : input) box.extend(p);
  const Vec3d centre = box.center();
  const Vec3d ext = box.extent();
  const double longest = std::max({ext.x, ext.y, ext.z});
  require(longest > 0.0 && std::isfinite(longest), "all points are equal (or the extent is not finite)");
  const double W = o.half_width;
  std::vector<Vec3d> points(input.size());
  for (std::size_t i = 0; i < input.size(); ++i) points[i] = input[i] - centre;
  const PointIndex index(points);
  ReconstructionResult result;
  result.sampling = estimate_sampling(index, {16, 2000, o.progress});
  result.resolution = o.resolution > 0 ? o.resolution : 0;
  if (o.resolution == 0 && o.voxel_size <= 0.0) result.resolution = auto_resolution(result.sampling, longest, W);
  const double h_final = o.voxel_size > 0.0 ? o.voxel_size : longest / (double(result.resolution) - 2.0 * (W + 2.0));
  const double side = longest / h_final + 2.0 * (W + 2.0);
  if (!(side <= double(o.max_resolution)))
    throw Error(ErrorCode::LimitExceeded, "reconstruct",
                "the final grid would have " + std::to_string(side) + " voxels along its longest side (max_resolution " +
                    std::to_string(o.max_resolution) + ")");
  auto log = [&](const std::string& line) {
    if (o.log) o.log(line);
  };

  if (o.resolution == 0 && o.voxel_size <= 0.0) {
    char chosen[200];
    std::snprintf(chosen, sizeof chosen, "resolution %d from the data: spacing %.4g, noise %.4g (world; %.2f and %.2f voxels)",
                  result.resolution, result.sampling.spacing, result.sampling.noise, result.sampling.spacing / h_final,
                  result.sampling.noise / h_final);
    log(chosen);
  }
  BBox local;
  local.min = box.min - centre;
  local.max = box.max - centre;

  // The start shell closes holes between samples up to its offset: at least kGapClosing times
  // the 90th percentile of the distance to the 8th nearest sample, or its flood fill leaks
  // into the inside and the flow collapses onto the points from both sides.
  const double gap = sample_gap(index, 8, 0.9, 4000);
  // Levels from the data unless given: the coarsest voxel no wider than the gap the shell
  // must close (coarser levels only close more: tunnels and gaps between nearby parts that
  // the points resolve), within [kMinAutoLevels, kMaxAutoLevels]; fewer when the coarsest
  // would have under 24 voxels along the longest side.
  int levels = o.levels;
  if (levels == 0) {
    const double ratio = kGapClosing * gap / h_final;
    levels = ratio >= 1.0 ? 1 + int(std::floor(std::log2(ratio))) : 1;
    levels = std::clamp(levels, kMinAutoLevels, kMaxAutoLevels);
  }
  while (levels > 1 && longest / (h_final * std::ldexp(1.0, levels - 1)) < 24.0) --levels;
  const double h_coarse = h_final * std::ldexp(1.0, levels - 1);
  const double shell_offset = std::min(16.0, std::max(o.shell_offset, kGapClosing * gap / h_coarse));
  const double pad = (shell_offset + W + 3.0) * h_coarse;
  const Vec3d origin = local.min - Vec3d{pad, pad, pad};

  NarrowBand band;
  double previous_noise = 0.0;  // final voxels: the last snap pass's noise estimate
  double previous_height_noise = 0.0;  // final voxels: its height fits' residual (no sagitta)
  char line[512];
  for (int level = 0; level < levels; ++level) {
    const auto t_level = Clock::now();
    const double h = h_final * std::ldexp(1.0, levels - 1 - level);
    ReconstructionStage stage;
    stage.level = level;
    stage.voxel_size = h;
    if (level == 0) {
      // The flow from the start shell.
      band = start_shell(index, local, origin, h, shell_offset, W, o.progress);
      stage.shell_offset = shell_offset;
      stage.seconds_start = seconds_since(t_level);
      // Cache of fits: the voxels within W + 2 of the start front.
      RedistanceOptions grow;
      grow.half_width = W + 2.0;
      grow.progress = o.progress;
      const NarrowBand cache = redistance(band, grow).band;
      PointFitFieldOptions fit_options;
      fit_options.neighbors = o.neighbors;
      fit_options.progress = o.progress;
      const auto t_fit = Clock::now();
      const std::vector<LocalFit> fits = point_fit_field(index, cache, fit_options).fits;
      stage.seconds_fit = seconds_since(t_fit);
      stage.fit_voxels = fits.size();
      MotionMeter meter;
      evolve::EvolutionOptions ev;
      ev.speed = fit_speed(cache, fits, index, o.neighbors, o.curvature_weight, meter);
      ev.steps = 1;
      ev.drift_tolerance = 0.1;  // the speed is constant along normals near the data: rare
      ev.progress.cancel = o.progress.cancel;
      ev.progress.stop = o.progress.stop;
      // One step per evolve call: between steps, sign changes that are not simple are
      // refused and ambiguous faces keep their decision (grid/topology_guard.hpp): the start shell's
      // topology is the result's (a part thinner than a coarse voxel, the bunny's ears,
      // otherwise broke off or grew handles depending on the sample set).
      const auto t_flow = Clock::now();
      if (!o.guard_flow) {
        // Unguarded: one evolve call, stopped by the mean |beta| near the front.
        ev.steps = o.max_steps;
        ev.stop_when = [&](const evolve::StepInfo& si) {
          stage.last_change = meter.take_mean() * si.dt / h;
          o.progress.step(0.5 * double(si.step) / o.max_steps / levels, "reconstruct");
          return stage.last_change < o.tolerance;
        };
        evolve::EvolutionResult r = evolve::evolve(band, ev);
        evolve::throw_if_stopped(r, "reconstruct");
        stage.steps = r.steps;
        stage.seconds_redistance = r.seconds.redistance;
        band = std::move(r.band);
      }
      for (int step = 1; o.guard_flow && step <= o.max_steps; ++step) {
        evolve::EvolutionResult r = evolve::evolve(band, ev);
        evolve::throw_if_stopped(r, "reconstruct");
        // A stop request ends each level's flow where it is; the remaining stages still run.
        if (r.stop == evolve::StopReason::Stopped) break;
        stage.seconds_redistance += r.seconds.redistance;
        TopologyGuardOptions guard;
        guard.eps = 1e-3 * h;
        guard.progress = o.progress;
        const double free_distance = o.free_distance * h;
        guard.free = [&](const Coord& c) { return index.nearest(r.band.world(c)).distance > free_distance; };
        TopologyGuardResult kept =
            guard_topology(band, r.band, std::vector<float>(r.band.values().begin(), r.band.values().end()), guard);
        const std::uint64_t refused = kept.refused_flips;
        r.band.swap_values(kept.values);
        if (refused > 0) {
          // Refused voxels hold the front where the band upkeep had moved on: redistance on
          // the domain grown by one voxel, as after a snap.
          stage.refused_flips += refused;
          const auto t_redistance = Clock::now();
          RedistanceOptions redo;
          redo.half_width = W;
          redo.progress = o.progress;
          r.band = redistance(reframed(r.band, {}, W - 1.0), redo).band;
          stage.seconds_redistance += seconds_since(t_redistance);
        }
        // Convergence: the mean motion of the voxels within one voxel of the front, measured
        // on the values after the topology control (the speed's own |beta| stays high where a
        // refused voxel pins the front).
        double moved = 0.0;
        std::uint64_t near = 0;
        {
          BandAccessor old_acc(band);
          for (std::uint32_t b = 0; b < r.band.brick_count(); ++b)
            r.band.for_each_active_in_brick(b, [&](const Coord& c, float u) {
              if (!(std::abs(double(u)) < h)) return;
              const std::optional<float> was = old_acc.probe(c);
              if (!was) return;
              moved += std::min(std::abs(double(u) - double(*was)), h);
              ++near;
            });
        }
        meter.take_mean();
        band = std::move(r.band);
        stage.steps = step;
        stage.last_change = near > 0 ? moved / double(near) / h : 0.0;
        o.progress.step(0.5 * double(step) / o.max_steps / levels, "reconstruct");
        if (stage.last_change < o.tolerance) break;
      }
      stage.seconds_flow = seconds_since(t_flow);
      stage.dropped_components = drop_unsupported_components(band, index, kSupportDistance * h, o.progress);
      if (stage.dropped_components > 0) {
        const auto t_redistance = Clock::now();
        RedistanceOptions redo;
        redo.progress = o.progress;
        band = redistance(band, redo).band;
        stage.seconds_redistance += seconds_since(t_redistance);
      }
      stage.converged = stage.last_change < o.tolerance;
    }
    if (level > 0 || levels == 1) {
      // The snap (on a single level: after the flow, with its own curvature).
      const NarrowBand coarse = std::move(band);
      const std::vector<float> coarse_curvature = mean_curvature_field(coarse);
      const auto t_up = Clock::now();
      band = level > 0 ? upsample(coarse, W, o.progress) : coarse;
      stage.seconds_start += seconds_since(t_up);
      // On the final level, clean data get clean_final_passes (the first pass's noise
      // estimate decides).
      int passes = o.snap_passes;
      bool refine = false;  // after a clean pass: the front is within ~0.1 voxel of the fits
      int unredistanced = 0;  // passes since the last redistance
      for (int pass = 0; pass < passes; ++pass) {
        const auto t_fit = Clock::now();
        SnapSettings settings;
        settings.neighbors = o.neighbors;
        settings.height_neighbors = std::max(o.neighbors, kHeightNeighbors);
        if (previous_noise >= kCleanNoise) {
          settings.noisy_height = true;
          settings.height_neighbors = std::max(settings.height_neighbors, noisy_height_neighbors(band, index.size(), h_final));
        } else if (previous_height_noise > 0.0) {  // clean so far: more points as the noise grows
          settings.height_neighbors = std::max(settings.height_neighbors,
                                               height_neighbors_for(front_density(band, index.size(), h_final),
                                                                    previous_height_noise));
        }
        settings.window = refine ? kRefineWindow : kSnapWindow;
        settings.fit_window = refine ? kRefineWindow : kFitWindow;
        settings.h_final = h_final;
        settings.guard = o.guard_snaps;
        const SnapPass snapped = snap_to_fits(band, index, settings, coarse, coarse_curvature, o.progress);
        previous_noise = snapped.noise * h / h_final;
        previous_height_noise = snapped.height_noise * h / h_final;
        stage.height_neighbors = settings.height_neighbors;
        if (pass == 0 && level == levels - 1 && snapped.clean) passes = std::max(passes, o.clean_final_passes);
        refine = snapped.clean;
        stage.second_order = snapped.clean;
        stage.height_fits += snapped.height_fits;
        stage.refused_flips += snapped.refused;
        stage.seconds_fit += seconds_since(t_fit);
        stage.fit_voxels += snapped.voxels;
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
        if (last || !snapped.clean) {
          const auto t_redistance = Clock::now();
          RedistanceOptions redo;
          redo.half_width = W;
          redo.progress = o.progress;
          band = redistance(reframed(band, {}, W - double(unredistanced)), redo).band;
          unredistanced = 0;
          stage.seconds_redistance += seconds_since(t_redistance);
        }
        o.progress.step((double(level) + double(pass + 1) / passes) / levels, "reconstruct");
        if (last) break;
      }
      if (level > 0) stage.converged = stage.last_change < o.tolerance;
    }
    stage.active_voxels = band.active_voxel_count();
    stage.seconds = seconds_since(t_level);
    std::snprintf(line, sizeof line,
                  "level %d: h %.4g, shell offset %.2f voxel, %s %d, change %.4f voxel, noise %.3f voxel (height fits %.3f), %s (%d points), smoothing %d, %llu voxels, %llu fits (%llu height); start %.3f s, "
                  "fits %.3f s, flow %.3f s, redistance %.3f s, total %.3f s",
                  level, h, stage.shell_offset, level == 0 ? "flow steps" : "snap passes", stage.steps, stage.last_change, stage.noise,
                  stage.height_noise, stage.second_order ? "second order" : "plane fits", stage.height_neighbors, stage.smoothing,
                  static_cast<unsigned long long>(stage.active_voxels), static_cast<unsigned long long>(stage.fit_voxels),
                  static_cast<unsigned long long>(stage.height_fits),
                  stage.seconds_start, stage.seconds_fit, stage.seconds_flow, stage.seconds_redistance, stage.seconds);
    log(line);
    if (o.log && o.log_topology) {
      // Debug aid: the topology of this level's zero level.
      MarchingCubesOptions mc;
      mc.progress = o.progress;
      const MeshMeasures m = measure_mesh(marching_cubes(band, mc).mesh);
      std::snprintf(line, sizeof line, "level %d: genus %g, components %llu, watertight %s, %llu sign changes refused, %llu stray components dropped", level, m.genus,
                    static_cast<unsigned long long>(m.components), m.watertight ? "yes" : "no",
                    static_cast<unsigned long long>(stage.refused_flips), static_cast<unsigned long long>(stage.dropped_components));
      log(line);
    }
    result.steps += stage.steps;
    result.stages.push_back(stage);
  }

  const auto t_mesh = Clock::now();
  result.band = reframed(band, centre, band.half_width());
  MarchingCubesOptions mc;
  mc.progress = o.progress;
  result.mesh = marching_cubes(result.band, mc).mesh;
  result.measures = measure_mesh(result.mesh);
  result.seconds_mesh = seconds_since(t_mesh);
  result.voxel_size = h_final;
  result.seconds = seconds_since(t_start);
  std::snprintf(line, sizeof line, "mesh: %zu triangles, %.3f s; total %.3f s", result.mesh.triangles.size(),
                result.seconds_mesh, result.seconds);
  log(line);
  return result;
}

}  // namespace levelset::apps
