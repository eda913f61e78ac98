#include "distance/brick_triangle_lists.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <string>

#include <tbb/parallel_for.h>

#include "core/error.hpp"
#include "core/huge_pages.hpp"
#include "core/index_hash_table.hpp"
#include "geometry/point_triangle.hpp"
#include "io/validate_mesh.hpp"

namespace levelset {

namespace {

struct Pair {
  std::uint64_t key;  // brick_key
  std::uint32_t triangle;
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
  const TrianglePlane plane = triangle_plane(a, b, c);
  const Vec3d& n = plane.n;
  const bool planar = plane.flat;
  const double half = 0.5 * (kBrickDim - 1) * h;  // brick box half extent (voxel centres)
  // The normal's rounding over the farthest brick centre considered (the triangle's box grown
  // by the margin and a brick): a constant per triangle.
  const double far = length(hi - lo) + 4 * half;
  const double reach = margin + half * (std::abs(n.x) + std::abs(n.y) + std::abs(n.z)) + plane.error * far;
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

// The lists from pairs in triangle order, without sorting the pairs: distinct bricks in
// first-seen order (a hash table), sorted by key (a few thousand where the pairs are millions),
// then each pair's triangle at its brick's next slot, so each list is in triangle order.
BrickTriangleLists group_by_brick(const std::vector<Pair>& pairs, double margin) {
  BrickTriangleLists lists;
  lists.margin = margin;
  std::vector<std::uint64_t> keys;  // distinct, first-seen order
  std::vector<std::uint64_t> count;
  std::vector<std::uint32_t> brick_of;
  resize_with_huge_pages(brick_of, pairs.size());
  IndexHashTable table(std::min<std::size_t>(pairs.size(), 4096));
  for (std::size_t i = 0; i < pairs.size(); ++i) {
    const std::uint64_t key = pairs[i].key;
    // Consecutive pairs mostly share a brick (a triangle's bricks, then its neighbour's).
    std::uint32_t id;
    if (i > 0 && pairs[i - 1].key == key) {
      id = brick_of[i - 1];
    } else {
      if (table.full()) table.grow([&](std::uint32_t k) { return keys[k]; });
      id = table.find_or_insert(key, std::uint32_t(keys.size()), [&](std::uint32_t k) { return keys[k] == key; });
      if (id == keys.size()) {
        keys.push_back(key);
        count.push_back(0);
      }
    }
    ++count[id];
    brick_of[i] = id;
  }
  std::vector<std::uint32_t> order(keys.size());
  for (std::uint32_t k = 0; k < order.size(); ++k) order[k] = k;
  std::sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) { return keys[a] < keys[b]; });
  std::vector<std::uint64_t> next(keys.size());  // per brick id: its next slot
  lists.bricks.reserve(keys.size());
  lists.offsets.reserve(keys.size() + 1);
  lists.offsets.push_back(0);
  for (std::uint32_t id : order) {
    next[id] = lists.offsets.back();
    lists.bricks.push_back(brick_from_key(keys[id]));
    lists.offsets.push_back(lists.offsets.back() + count[id]);
  }
  resize_with_huge_pages(lists.triangles, pairs.size());
  for (std::size_t i = 0; i < pairs.size(); ++i) lists.triangles[next[brick_of[i]]++] = pairs[i].triangle;
  return lists;
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

  // Pass 2: fill (in triangle order: each triangle's pairs at its offset).
  std::vector<Pair> pairs;
  resize_with_huge_pages(pairs, counts[nt]);
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
  options.progress.step(0.6, "bin");
  return group_by_brick(pairs, options.margin);
}

}  // namespace levelset
