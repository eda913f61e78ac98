#include "distance/brick_triangle_lists.hpp"

#include <atomic>
#include <cmath>
#include <string>

#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>

#include "core/error.hpp"
#include "io/validate_mesh.hpp"

namespace levelset {

namespace {

struct Pair {
  std::uint64_t key;
  std::uint32_t triangle;
  bool operator<(const Pair& o) const { return key != o.key ? key < o.key : triangle < o.triangle; }
};

// Visits the bricks near one triangle: those whose voxel-centre box meets the triangle's
// margin-inflated bounding box and lies within margin of the triangle's plane.
template <typename F>
void for_each_brick_near(const Vec3d& a, const Vec3d& b, const Vec3d& c, const GridFrame& frame,
                         double margin, F&& visit) {
  const double h = frame.voxel_size;
  const Vec3d lo = min(min(a, b), c) - Vec3d{margin, margin, margin};
  const Vec3d hi = max(max(a, b), c) + Vec3d{margin, margin, margin};
  Coord blo, bhi;
  for (int ax = 0; ax < 3; ++ax) {
    // Voxels with centres in [lo, hi], then their bricks.
    const double i0 = std::ceil((lo[ax] - frame.origin[ax]) / h);
    const double i1 = std::floor((hi[ax] - frame.origin[ax]) / h);
    if (i0 > i1) return;
    if (i0 < -double(kVoxelCoordLimit) || i1 >= double(kVoxelCoordLimit))
      throw Error(ErrorCode::LimitExceeded, "mesh",
                  "triangle reaches beyond the voxel index range +-" + std::to_string(kVoxelCoordLimit) +
                      "; increase the voxel size");
    blo[ax] = static_cast<std::int32_t>(std::floor(i0 / kBrickDim));
    bhi[ax] = static_cast<std::int32_t>(std::floor(i1 / kBrickDim));
  }
  Vec3d n = cross(b - a, c - a);
  const double len = length(n);
  const bool planar = len > 0.0 && std::isfinite(len);
  if (planar) n = n / len;
  const double half = 0.5 * (kBrickDim - 1) * h;  // brick box half extent (voxel centres)
  const double reach = margin + half * (std::abs(n.x) + std::abs(n.y) + std::abs(n.z));
  for (int z = blo.z; z <= bhi.z; ++z)
    for (int y = blo.y; y <= bhi.y; ++y)
      for (int x = blo.x; x <= bhi.x; ++x) {
        const Coord bc{x, y, z};
        if (planar) {
          const Coord o = brick_origin(bc);
          const Vec3d center = frame.origin + Vec3d{o.x + 3.5, o.y + 3.5, o.z + 3.5} * h;
          if (std::abs(dot(n, center - a)) > reach) continue;
        }
        visit(bc);
      }
}

}  // namespace

BrickTriangleLists bin_triangles_to_bricks(const TriangleMesh& mesh, const BinTrianglesOptions& options) {
  NarrowBand validate(options.frame);
  (void)validate;
  if (!(std::isfinite(options.margin) && options.margin >= 0))
    throw Error(ErrorCode::InvalidArgument, "margin", "must be finite and >= 0");
  const std::size_t nt = mesh.triangles.size();
  validate_mesh(mesh);

  // Pass 1: count pairs per triangle (so the pair array is allocated once, exactly, and an
  // absurd total is refused before allocating).
  std::vector<std::uint64_t> counts(nt + 1, 0);
  std::atomic<std::uint64_t> total{0};
  std::atomic<bool> over{false};
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, nt, 256), [&](const tbb::blocked_range<std::size_t>& r) {
    options.progress.check("bin");
    for (std::size_t t = r.begin(); t != r.end() && !over.load(std::memory_order_relaxed); ++t) {
      const auto& tri = mesh.triangles[t];
      std::uint64_t n = 0;
      for_each_brick_near(mesh.vertices[tri[0]], mesh.vertices[tri[1]], mesh.vertices[tri[2]],
                          options.frame, options.margin, [&](const Coord&) {
                            if (++n > options.max_pairs) over.store(true);
                          });
      counts[t + 1] = n;
      if (total.fetch_add(n) + n > options.max_pairs) over.store(true);
    }
  });
  if (over.load())
    throw Error(ErrorCode::LimitExceeded, "mesh",
                "the mesh covers more than " + std::to_string(options.max_pairs) +
                    " brick-triangle pairs at this voxel size (the voxel budget); increase the voxel size");
  for (std::size_t t = 0; t < nt; ++t) counts[t + 1] += counts[t];
  options.progress.step(0.3, "bin");

  // Pass 2: fill, then sort by (brick key, triangle).
  std::vector<Pair> pairs(counts[nt]);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, nt, 256), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t t = r.begin(); t != r.end(); ++t) {
      const auto& tri = mesh.triangles[t];
      std::uint64_t at = counts[t];
      for_each_brick_near(mesh.vertices[tri[0]], mesh.vertices[tri[1]], mesh.vertices[tri[2]],
                          options.frame, options.margin, [&](const Coord& bc) {
                            pairs[at++] = {brick_key(bc), static_cast<std::uint32_t>(t)};
                          });
    }
  });
  tbb::parallel_sort(pairs.begin(), pairs.end());
  options.progress.step(0.7, "bin");

  BrickTriangleLists lists;
  lists.margin = options.margin;
  lists.triangles.resize(pairs.size());
  lists.offsets.push_back(0);
  for (std::size_t i = 0; i < pairs.size(); ++i) {
    if (i == 0 || pairs[i].key != pairs[i - 1].key) {
      if (i > 0) lists.offsets.push_back(i);
      lists.bricks.push_back(brick_from_key(pairs[i].key));
    }
    lists.triangles[i] = pairs[i].triangle;
  }
  if (!pairs.empty()) lists.offsets.push_back(pairs.size());
  return lists;
}

}  // namespace levelset
