// reconstruct_surface's grids: the start shell, reframing and upsampling (reconstruction_parts.hpp).
#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <deque>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "apps/reconstruction_parts.hpp"
#include "core/error.hpp"
#include "distance/redistance.hpp"
#include "grid/band_builder.hpp"
#include "grid/build_from_sdf.hpp"
#include "grid/for_each_active_parallel.hpp"
#include "grid/sign_components.hpp"

namespace levelset::apps::detail {

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
  // Distances to the points, in voxels, exact wherever they decide something: the flood
  // fill's test (> offset) and the band's values (|d - offset| <= W). A voxel farther than
  // `needed` only has to read as farther: a block of kBlock^3 voxels whose centre is farther
  // than needed + its half-diagonal gets one nearest query and that lower bound (most of the
  // grid lies far from the points: ~8 % of a 20k-point reconstruction was this loop). Same
  // band as exact distances everywhere (build_from_sdf's block skipping stays conservative
  // on a lower bound).
  const double needed = offset + half_width + 2.0;
  constexpr long kBlock = 4;
  const long bx = (nx + kBlock - 1) / kBlock, by = (ny + kBlock - 1) / kBlock, bz = (nz + kBlock - 1) / kBlock;
  std::vector<float> dist(total);
  tbb::parallel_for(tbb::blocked_range<long>(0, bz), [&](const tbb::blocked_range<long>& r) {
    for (long kb = r.begin(); kb != r.end(); ++kb) {
      progress.check("reconstruct start");
      const long k0 = kb * kBlock, k1 = std::min(nz, k0 + kBlock);
      for (long jb = 0; jb < by; ++jb)
        for (long ib = 0; ib < bx; ++ib) {
          const long j0 = jb * kBlock, j1 = std::min(ny, j0 + kBlock), i0 = ib * kBlock, i1 = std::min(nx, i0 + kBlock);
          const Vec3d lo{double(i0), double(j0), double(k0)}, hi{double(i1 - 1), double(j1 - 1), double(k1 - 1)};
          const double half_diagonal = 0.5 * length(hi - lo);
          const double centre = index.nearest(origin + (lo + hi) * (0.5 * h)).distance / h;
          const bool far = centre - half_diagonal > needed;
          for (long k = k0; k < k1; ++k)
            for (long j = j0; j < j1; ++j)
              for (long i = i0; i < i1; ++i)
                dist[at(i, j, k)] = far ? float(centre - half_diagonal)
                                        : float(index.nearest(origin + Vec3d{double(i), double(j), double(k)} * h).distance / h);
        }
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
  // build_from_sdf also asks at block centres between voxels: the nearest voxel's value is
  // then moved toward zero by the distance to that voxel, so |sdf| stays a lower bound of the
  // distance to the band's zero level (its contract; skipping a block on the voxel's value
  // could miss a voxel at the band's edge).
  auto sdf = [&](const Vec3d& p) {
    const Vec3d q = (p - origin) / h;
    const long i = std::clamp(long(std::lround(q.x)), 0L, nx - 1), j = std::clamp(long(std::lround(q.y)), 0L, ny - 1),
               k = std::clamp(long(std::lround(q.z)), 0L, nz - 1);
    const std::size_t n = at(i, j, k);
    const double v = double(dist[n]) - offset;
    double signed_v = outside[n] ? v : (v < 0.0 ? v : -v - 1e-3);
    const double snap = length(q - Vec3d{double(i), double(j), double(k)});
    if (snap > 1e-6) signed_v = signed_v > 0.0 ? std::max(0.0, signed_v - snap) : std::min(0.0, signed_v + snap);
    return signed_v * h;
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

}  // namespace levelset::apps::detail
