#include "apps/csg.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numbers>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "core/error.hpp"
#include "distance/redistance.hpp"
#include "evolve/evolution.hpp"
#include "grid/band_accessor.hpp"
#include "grid/band_builder.hpp"
#include "grid/interpolate.hpp"

namespace levelset::apps {

namespace {

constexpr int kHalo = 10;  // a brick plus one voxel each side

// Result bricks within one result voxel of the allocated bricks of `in` (keys, unsorted).
void collect_candidates(const NarrowBand& in, const GridFrame& out, std::uint64_t max_bricks,
                        std::vector<std::uint64_t>& keys) {
  const double h = out.voxel_size;
  const double lim = double(kVoxelCoordLimit) - 16.0;
  std::uint64_t total = 0;
  auto range = [&](const Brick& br, Coord& lo, Coord& hi) {
    const Vec3d a = in.world(brick_origin(br.coord));
    const Vec3d b = in.world(brick_origin(br.coord) + Coord{kBrickDim - 1, kBrickDim - 1, kBrickDim - 1});
    for (int ax = 0; ax < 3; ++ax) {
      const double l = std::floor((a[ax] - out.origin[ax]) / h) - 1.0;
      const double u = std::ceil((b[ax] - out.origin[ax]) / h) + 1.0;
      if (!(l > -lim && u < lim))
        throw Error(ErrorCode::LimitExceeded, "csg", "the inputs leave the result grid's index range");
      lo[ax] = std::int32_t(l) >> kBrickLog2;
      hi[ax] = std::int32_t(u) >> kBrickLog2;
    }
  };
  // Count first (duplicates included) so that nothing giant is allocated.
  for (const Brick& br : in.bricks()) {
    Coord lo, hi;
    range(br, lo, hi);
    total += std::uint64_t(hi.x - lo.x + 1) * std::uint64_t(hi.y - lo.y + 1) * std::uint64_t(hi.z - lo.z + 1);
    if (total > 8 * max_bricks)
      throw Error(ErrorCode::LimitExceeded, "csg", "more candidate bricks than max_bricks (voxel size too fine?)");
  }
  keys.reserve(keys.size() + total);
  for (const Brick& br : in.bricks()) {
    Coord lo, hi;
    range(br, lo, hi);
    for (int z = lo.z; z <= hi.z; ++z)
      for (int y = lo.y; y <= hi.y; ++y)
        for (int x = lo.x; x <= hi.x; ++x) keys.push_back(brick_key({x, y, z}));
  }
}

bool combine_far_inside(CsgOp op, bool a, bool b) {
  switch (op) {
    case CsgOp::Union: return a || b;
    case CsgOp::Intersection: return a && b;
    case CsgOp::Difference: return a && !b;
  }
  return false;
}

double taper(double s) {  // 1 for s <= 1, half cosine to 0 at s = 2
  if (s <= 1.0) return 1.0;
  if (s >= 2.0) return 0.0;
  return 0.5 * (1.0 + std::cos(std::numbers::pi * (s - 1.0)));
}

}  // namespace

CsgOp csg_op_from_name(std::string_view name) {
  if (name == "union") return CsgOp::Union;
  if (name == "intersection") return CsgOp::Intersection;
  if (name == "difference") return CsgOp::Difference;
  throw Error(ErrorCode::InvalidArgument, std::string(name), "unknown CSG operation; known: union, intersection, difference");
}

std::string_view csg_op_name(CsgOp op) {
  switch (op) {
    case CsgOp::Union: return "union";
    case CsgOp::Intersection: return "intersection";
    case CsgOp::Difference: return "difference";
  }
  return "?";
}

double csg_combine(CsgOp op, double a, double b) {
  switch (op) {
    case CsgOp::Union: return std::min(a, b);
    case CsgOp::Intersection: return std::max(a, b);
    case CsgOp::Difference: return std::max(a, -b);
  }
  return a;
}

double seam_region_of_influence(const NarrowBand& a, const NarrowBand& b, double radius, const Vec3d& p) {
  BandAccessor acc_a(a), acc_b(b);
  const double va = std::abs(sample_trilinear(acc_a, a, p)), vb = std::abs(sample_trilinear(acc_b, b, p));
  // A clamped sample (at the band limit) tells no distance: treat as far.
  if (va >= 0.999 * a.background() || vb >= 0.999 * b.background()) return 0.0;
  return taper(std::max(va, vb) / radius);
}

CsgResult csg(const NarrowBand& a, const NarrowBand& b, const CsgOptions& options) {
  const auto t0 = std::chrono::steady_clock::now();
  if (options.voxel_size != 0 && !(std::isfinite(options.voxel_size) && options.voxel_size > 0))
    throw Error(ErrorCode::InvalidArgument, "csg voxel_size", "must be finite and > 0 (or 0: the finer input's)");
  if (options.half_width != 0 && !(std::isfinite(options.half_width) && options.half_width >= 2 && options.half_width <= 1024))
    throw Error(ErrorCode::InvalidArgument, "csg half_width", "must be in [2, 1024] (or 0: the larger input's)");
  if (!(std::isfinite(options.seam_time) && options.seam_time >= 0))
    throw Error(ErrorCode::InvalidArgument, "csg seam_time", "must be finite and >= 0");
  if (options.seam_time > 0 && !(std::isfinite(options.seam_radius) && options.seam_radius > 0))
    throw Error(ErrorCode::InvalidArgument, "csg seam_radius", "must be finite and > 0 when fairing the seam");

  // 1. The result frame.
  GridFrame frame;
  const NarrowBand& finer = b.voxel_size() < a.voxel_size() ? b : a;
  frame.voxel_size = options.voxel_size > 0 ? options.voxel_size : finer.voxel_size();
  frame.origin = options.voxel_size > 0 ? a.origin() : finer.origin();
  frame.half_width = options.half_width > 0 ? options.half_width : std::max(std::max(a.half_width(), b.half_width()), 2.0);
  const double h = frame.voxel_size;

  // 2. Candidate bricks and their values.
  std::vector<std::uint64_t> keys;
  collect_candidates(a, frame, options.max_bricks, keys);
  collect_candidates(b, frame, options.max_bricks, keys);
  std::sort(keys.begin(), keys.end());
  keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
  if (keys.size() > options.max_bricks)
    throw Error(ErrorCode::LimitExceeded, "csg", std::to_string(keys.size()) + " candidate bricks exceed max_bricks");
  options.progress.step(0.05, "csg candidates");

  // Values below both inputs' limits carry a distance; the intermediate band's half-width.
  const double limit = std::min(frame.half_width * h, 0.999 * std::min(double(a.background()), double(b.background())));
  GridFrame mid = frame;
  mid.half_width = std::max(1.0, limit / h);
  const float clamp = float(mid.half_width * h);
  BandBuilder builder(mid);
  const CsgOp op = options.op;
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, keys.size(), 4), [&](const tbb::blocked_range<std::size_t>& r) {
    options.progress.check("csg");
    BandAccessor acc_a(a), acc_b(b);
    std::vector<float> halo(kHalo * kHalo * kHalo);
    float dense[kBrickVoxels];
    for (std::size_t k = r.begin(); k != r.end(); ++k) {
      const Coord brick = brick_from_key(keys[k]);
      const Coord o = brick_origin(brick) - Coord{1, 1, 1};
      for (int z = 0; z < kHalo; ++z)
        for (int y = 0; y < kHalo; ++y)
          for (int x = 0; x < kHalo; ++x) {
            const Coord c = o + Coord{x, y, z};
            const Vec3d p = frame.origin + Vec3d{double(c.x), double(c.y), double(c.z)} * h;
            halo[std::size_t(x + kHalo * (y + kHalo * z))] =
                float(csg_combine(op, sample_trilinear(acc_a, a, p), sample_trilinear(acc_b, b, p)));
          }
      BrickMask active{}, inside{};
      for (int n = 0; n < kBrickVoxels; ++n) {
        const Coord l = local_coord(n);
        const std::size_t i = std::size_t((l.x + 1) + kHalo * ((l.y + 1) + kHalo * (l.z + 1)));
        const float v = halo[i];
        const bool in = v < 0.0f;
        bool crossing = false;
        for (std::size_t step : {std::size_t(1), std::size_t(kHalo), std::size_t(kHalo * kHalo)})
          crossing = crossing || ((halo[i + step] < 0.0f) != in) || ((halo[i - step] < 0.0f) != in);
        inside.assign(n, in);
        active.assign(n, crossing || std::abs(v) < limit);
        // Stored values keep their sign and stay within the intermediate band's limit.
        dense[n] = std::clamp(v, -clamp, clamp);
      }
      builder.add_brick(brick, active, inside, dense);
    }
  });
  NarrowBand combined = builder.finish(combine_far_inside(op, a.far_inside(), b.far_inside()));
  options.progress.step(0.4, "csg redistance");

  // 3. A proper distance band again.
  RedistanceOptions ro;
  ro.half_width = frame.half_width;
  ro.progress = options.progress;
  CsgResult result;
  result.candidate_bricks = keys.size();
  result.band = redistance(combined, ro).band;

  // 4. Seam fairing: mean curvature flow restricted to the region of influence.
  if (options.seam_time > 0) {
    options.progress.step(0.5, "csg seam fairing");
    evolve::EvolutionOptions eo;
    eo.speed.name = "seam-mean-curvature";
    eo.speed.needs = evolve::kNeedsMean | evolve::kNeedsRoi;
    eo.speed.has_advective = false;
    eo.speed.has_parabolic = true;
    eo.speed.diffusion = 1.0;  // |roi| <= 1
    eo.speed.eval = [](const evolve::SpeedBatch& s, const evolve::SpeedOutput& out) {
      for (int i = 0; i < s.count; ++i) {
        out.advective[i] = 0.0f;
        out.parabolic[i] = -s.mean[i] * s.roi[i];
      }
    };
    const double radius = options.seam_radius;
    eo.fields.roi = [&a, &b, radius](const Vec3d& p) { return seam_region_of_influence(a, b, radius, p); };
    eo.time = options.seam_time;
    eo.redistance_every = options.seam_redistance_every;
    eo.progress = options.progress;
    evolve::EvolutionResult er = evolve::evolve(result.band, eo);
    evolve::throw_if_stopped(er, "csg seam fairing");
    result.band = std::move(er.band);
    result.seam_steps = er.steps;
    result.seam_time = er.time;
  }
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return result;
}

}  // namespace levelset::apps
