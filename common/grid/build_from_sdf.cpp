#include "grid/build_from_sdf.hpp"

#include <atomic>
#include <chrono>
#include <cmath>
#include <string>

#include <tbb/parallel_for.h>

#include "core/error.hpp"
#include "core/text.hpp"
#include "grid/band_builder.hpp"

namespace levelset {

namespace {

struct BlockSearch {
  const SdfFunction& sdf;
  const NarrowBand& frame_band;  // for world() only
  double band_world;             // W*h
  std::vector<Coord> leaves;
  std::uint64_t calls = 0;

  // Region [lo, hi) in brick coordinates.
  void descend(const Coord& lo, const Coord& hi) {
    const double h = frame_band.voxel_size();
    Vec3d c_idx, half;
    for (int a = 0; a < 3; ++a) {
      const double first = double(lo[a]) * kBrickDim, last = double(hi[a]) * kBrickDim - 1.0;
      c_idx[a] = 0.5 * (first + last);
      half[a] = 0.5 * (last - first) * h;
    }
    const Vec3d center = frame_band.origin() + c_idx * h;
    const double d = sdf(center);
    ++calls;
    if (!std::isfinite(d))
      throw Error(ErrorCode::NonFinite, "sdf", "signed distance function returned NaN or Inf");
    // Small relative slack keeps the test conservative under rounding.
    if (std::abs(d) > length(half) + band_world + 1e-9 * (1.0 + std::abs(d))) return;
    const Coord ext = hi - lo;
    if (ext.x == 1 && ext.y == 1 && ext.z == 1) {
      leaves.push_back(lo);
      return;
    }
    Coord mid = lo;
    for (int a = 0; a < 3; ++a) mid[a] = lo[a] + (ext[a] > 1 ? ext[a] / 2 : ext[a]);
    for (int oz = 0; oz < 2; ++oz)
      for (int oy = 0; oy < 2; ++oy)
        for (int ox = 0; ox < 2; ++ox) {
          const Coord l{ox ? mid.x : lo.x, oy ? mid.y : lo.y, oz ? mid.z : lo.z};
          const Coord u{ox ? hi.x : mid.x, oy ? hi.y : mid.y, oz ? hi.z : mid.z};
          if (l.x < u.x && l.y < u.y && l.z < u.z) descend(l, u);
        }
  }
};

}  // namespace

GridFrame frame_for_resolution(const BBox& bounds, int resolution, double half_width) {
  if (bounds.empty() || !isfinite(bounds.min) || !isfinite(bounds.max))
    throw Error(ErrorCode::InvalidArgument, "bounds", "empty or non-finite bounding box");
  if (!(half_width >= 1.0))
    throw Error(ErrorCode::InvalidArgument, "band", "half-width must be >= 1 voxel");
  if (resolution <= 2.0 * half_width + 1.0 || resolution > (1 << 20))
    throw Error(ErrorCode::InvalidArgument, "resolution",
                "must be in (2*band+1, 2^20], got " + std::to_string(resolution));
  double longest = bounds.longest_side();
  if (!(longest > 0)) longest = 1.0;  // a point or a flat box: still give a usable grid
  GridFrame f;
  f.half_width = half_width;
  f.voxel_size = longest / (resolution - 2.0 * half_width);
  const double pad = half_width * f.voxel_size;
  f.origin = bounds.min - Vec3d{pad, pad, pad};
  return f;
}

SdfBuildResult build_from_sdf(const SdfFunction& sdf, const BBox& surface_bounds,
                              const SdfBuildOptions& options) {
  const auto t0 = std::chrono::steady_clock::now();
  const NarrowBand frame_band(options.frame);  // validates the frame
  const double h = options.frame.voxel_size;
  const double band_world = options.frame.half_width * h;
  if (surface_bounds.empty() || !isfinite(surface_bounds.min) || !isfinite(surface_bounds.max))
    throw Error(ErrorCode::InvalidArgument, "bounds", "empty or non-finite surface bounds");

  // Index box of all voxels within W*h (+1 voxel) of the surface bounds, in bricks.
  Coord lo, hi;
  double domain = 1.0;
  for (int a = 0; a < 3; ++a) {
    const double imin = std::floor((surface_bounds.min[a] - band_world - options.frame.origin[a]) / h) - 1;
    const double imax = std::ceil((surface_bounds.max[a] + band_world - options.frame.origin[a]) / h) + 1;
    if (!(imin >= -double(kVoxelCoordLimit) && imax < double(kVoxelCoordLimit)))
      throw Error(ErrorCode::LimitExceeded, "voxel_size",
                  "domain needs voxel indices beyond +-" + std::to_string(kVoxelCoordLimit) +
                      "; increase the voxel size");
    domain *= (imax - imin + 1);
    lo[a] = static_cast<std::int32_t>(std::floor(imin / kBrickDim));
    hi[a] = static_cast<std::int32_t>(std::floor(imax / kBrickDim)) + 1;
  }
  if (domain > double(options.max_domain_voxels))
    throw Error(ErrorCode::LimitExceeded, "voxel_size",
                "domain of " + format_number(domain) + " voxels exceeds the budget of " +
                    std::to_string(options.max_domain_voxels) + "; increase the voxel size");

  BlockSearch search{sdf, frame_band, band_world, {}, 0};
  search.descend(lo, hi);
  options.progress.step(0.0, "bricks");

  BandBuilder builder(options.frame);
  std::atomic<std::uint64_t> done{0};
  const std::size_t n = search.leaves.size();
  const std::size_t batch = 256;
  for (std::size_t start = 0; start < n; start += batch) {
    const std::size_t end = std::min(n, start + batch);
    tbb::parallel_for(start, end, [&](std::size_t i) {
      const Coord b = search.leaves[i];
      const Coord o = brick_origin(b);
      alignas(64) float dense[kBrickVoxels];
      BrickMask active, inside;
      for (int idx = 0; idx < kBrickVoxels; ++idx) {
        const double d = sdf(frame_band.world(o + local_coord(idx)));
        if (!std::isfinite(d))
          throw Error(ErrorCode::NonFinite, "sdf", "signed distance function returned NaN or Inf");
        const float f = static_cast<float>(d);
        dense[idx] = f;
        if (f < 0.0f) inside.set(idx);
        if (std::abs(d) <= band_world) active.set(idx);
      }
      if (!active.none()) builder.add_brick(b, active, inside, dense);
      done.fetch_add(1, std::memory_order_relaxed);
    });
    options.progress.step(double(end) / double(n), "bricks");
  }

  SdfBuildResult result{builder.finish(false), n, search.calls + n * kBrickVoxels, 0.0};
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return result;
}

}  // namespace levelset
