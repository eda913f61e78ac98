// Internal to the characteristic scan (characteristic_scan.hpp): scan conversion of convex
// polyhedra into a per-voxel minimum of exact point-triangle distances, and the triangle
// frames the polyhedra are built from. Not a public API (namespace levelset::scan_detail).
//
// Polyhedron: half-spaces g . x <= c (at most 24) and a world box containing them.
// MinField: per voxel of a BrickSet the best (distance, triangle) so far, minimised atomically
//   (order independent: the same result for any thread count).
// Scanner::scan: visits the voxels inside a polyhedron column by column along its box's
//   longest axis and offers each its exact distance to one triangle, skipping voxels whose
//   plane distance already bounds it out. Cost: O(columns + voxels inside). Threading: one
//   Scanner per task, the MinField shared.
// triangle_frame: a triangle's unit normal, edge normals and the rounding margin of its
//   plane bound.
#pragma once

#include <atomic>
#include <bit>
#include <cstdint>
#include <limits>

#include <tbb/parallel_for.h>

#include "core/huge_pages.hpp"
#include "core/uninitialized_vector.hpp"
#include "distance/brick_set.hpp"
#include "distance/characteristic_scan.hpp"
#include "grid/narrow_band.hpp"
#include "io/triangle_mesh.hpp"

namespace levelset::scan_detail {

// A convex polyhedron: half-spaces g . x <= c and a world box containing it.
struct Polyhedron {
  Vec3d g[24];
  double c[24];
  int planes = 0;
  Vec3d lo, hi;

  void add(const Vec3d& normal, double offset) {
    if (planes < 24) {
      g[planes] = normal;
      c[planes] = offset;
      ++planes;
    }
  }
  // g . x <= g . point + slack
  void add_through(const Vec3d& normal, const Vec3d& point, double slack) { add(normal, dot(normal, point) + slack); }
  void box_of(const Vec3d* points, int n) {
    lo = hi = points[0];
    for (int i = 1; i < n; ++i) {
      lo = min(lo, points[i]);
      hi = max(hi, points[i]);
    }
  }
};

inline Vec3d unit(const Vec3d& v) {
  const double l = length(v);
  return l > 0 ? v / l : Vec3d{0, 0, 0};
}

// Per voxel: (float bits of the distance << 32) | triangle, minimised atomically. Non-negative
// floats order like their bits, so the minimum is the nearest triangle, ties to the lowest.
class MinField {
 public:
  // Cells allocated uninitialised, their pages faulted in by one call (prefault_for_write: a
  // std::vector of atomics zeroed them on one thread first, a trap per 4 KiB page of ~100 MB
  // for a dense mesh), then set to empty in parallel.
  explicit MinField(const BrickSet& set) : set_(set) {
    const std::size_t n = set.bricks.size() * std::size_t(kBrickVoxels);
    resize_with_huge_pages(cells_, n);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 1 << 14), [&](const auto& r) {
      for (std::size_t i = r.begin(); i != r.end(); ++i) cells_[i] = kEmpty;
    });
  }
  static constexpr std::uint64_t kEmpty = ~std::uint64_t{0};

  const BrickSet& set() const { return set_; }
  std::size_t size() const { return cells_.size(); }
  std::uint64_t load(std::size_t i) const { return cell(i).load(std::memory_order_relaxed); }
  // The best distance offered so far (+inf: none). Another thread may lower it at any time;
  // a value above it can never win, so callers may skip computing such values.
  float best(std::size_t cell) const {
    const std::uint64_t v = this->cell(cell).load(std::memory_order_relaxed);
    return v == kEmpty ? std::numeric_limits<float>::infinity() : std::bit_cast<float>(std::uint32_t(v >> 32));
  }
  void offer(std::size_t cell, float distance, std::uint32_t tri) {
    const std::uint64_t value = (std::uint64_t(std::bit_cast<std::uint32_t>(distance)) << 32) | tri;
    std::atomic_ref<std::uint64_t> c = this->cell(cell);
    std::uint64_t old = c.load(std::memory_order_relaxed);
    while (value < old && !c.compare_exchange_weak(old, value, std::memory_order_relaxed)) {
    }
  }

 private:
  std::atomic_ref<std::uint64_t> cell(std::size_t i) const { return std::atomic_ref<std::uint64_t>(cells_[i]); }
  const BrickSet& set_;
  mutable UninitializedVector<std::uint64_t> cells_;  // accessed through atomic_ref once filled
};

// A lower bound of the distance to the scanned triangle inside a polyhedron, sharper than its
// plane's in the wedges and cones: the distance to the feature the polyhedron belongs to, a
// vertex (point) or an edge's line, less `margin`. In a vertex's cone the triangle's closest
// point is the vertex, in an edge's wedge a point of the edge; the polyhedra's slack lets in
// points a little nearer the triangle than the feature, which the margin covers. Overlapping
// wedges and cones (across holes, beyond borders, in concave corners and thin plates, where
// several features lie within W h) are then skipped where a nearer triangle is known.
struct FeatureBound {
  enum class Kind { none, point, line } kind = Kind::none;
  Vec3d origin, axis;  // the vertex, or a point of the edge's line and its unit direction
  double margin = 0;
};

class Scanner {
 public:
  Scanner(const TriangleMesh& mesh, MinField& field, const GridFrame& frame)
      : mesh_(mesh), field_(field), frame_(frame) {
    h_ = frame.voxel_size;
    r_ = frame.half_width * h_;
    band2_ = r_ * r_;
    slack_ = 1e-7 * h_;
  }
  std::uint64_t evaluations = 0, polyhedra = 0;

  // Scan-converts p: voxels inside get their distance to triangle tri, whose unit normal is n
  // (zero when degenerate). Voxels whose distance to the triangle's plane, less
  // plane_margin (TriangleFrame), already exceeds their best distance (overlapping
  // polyhedra, common where the band is wider than the surface's radius of curvature) are
  // skipped: that bounds the distance from below, so they could not win.
  // `feature` (optional) adds FeatureBound's lower bound to the plane's.
  void scan(const Polyhedron& p, std::uint32_t tri, const Vec3d& n, double plane_margin,
            const FeatureBound& feature = {});

 private:
  template <FeatureBound::Kind Kind>
  void scan_with(const Polyhedron& p, std::uint32_t tri, const Vec3d& n, double plane_margin,
                 const FeatureBound& feature);
  static constexpr std::size_t kNoCell = ~std::size_t{0};
  std::size_t cell_of(const Coord& voxel) {
    const Coord b = brick_of(voxel);
    if (!(b == cached_brick_) || !cached_valid_) {
      cached_brick_ = b;
      cached_valid_ = true;
      cached_slot_ = field_.set().slot_of(b);
    }
    if (cached_slot_ == kNoBrick) return kNoCell;
    return std::size_t(cached_slot_) * kBrickVoxels + std::size_t(local_index(voxel));
  }
  const TriangleMesh& mesh_;
  MinField& field_;
  const GridFrame& frame_;
  double h_ = 0, r_ = 0, band2_ = 0, slack_ = 0;
  Coord cached_brick_;
  bool cached_valid_ = false;
  std::uint32_t cached_slot_ = kNoBrick;

 public:
  double slack() const { return slack_; }
  double voxel_size() const { return h_; }
  double radius() const { return r_; }
};

// One triangle's plane and its edges' outward in-plane normals (none for a degenerate one).
struct TriangleFrame {
  Vec3d v[3];
  Vec3d n;     // unit normal (zero when degenerate)
  Vec3d m[3];  // edge k = (v_k, v_k+1): outward in-plane unit normal
  bool flat = false;
  double scale = 0;  // longest edge
  // |n . (x - v0)| - plane_margin bounds the distance from below at every x within the band
  // of the triangle (+inf: no bound, for slivers whose computed normal is too inaccurate).
  double plane_margin = std::numeric_limits<double>::infinity();
};

TriangleFrame triangle_frame(const TriangleMesh& mesh, std::uint32_t t, double r, double h);

}  // namespace levelset::scan_detail
