// DenseGrid: a uniform box of nodes for the dense applications (fast marching, paths,
// Voronoi regions).
//
// Node (i,j,k), 0 <= i < nx etc., sits at world position origin + h*(i,j,k); arrays over
// the grid are flat, x fastest: index = i + nx*(j + ny*k). The grid covers the closed box
// [origin, origin + h*(n-1)] on each axis.
// Building: from world bounds and either a voxel size or a resolution R (h = longest side
//   / R, so about R+1 nodes along the longest side); the box is covered, never shrunk.
// Errors (thrown): Error{InvalidArgument} for empty or non-finite bounds, h <= 0 or not
//   finite, R < 2, fewer than 2 nodes on an axis; Error{LimitExceeded} when the node count
//   exceeds max_voxels (checked before anything is allocated) or an axis exceeds 2^30.
// Cost: O(1). Threading: plain data.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>
#include <string_view>

#include "core/bbox.hpp"
#include "grid/narrow_band.hpp"
#include "core/vec3.hpp"

namespace levelset::apps {

// Default cap on dense grid nodes: 2^27 (~134 M nodes; the fast march holds about 24 bytes
// per node, so ~3.2 GiB).
inline constexpr std::uint64_t kDefaultMaxGridVoxels = std::uint64_t{1} << 27;

struct DenseGrid {
  int nx = 0, ny = 0, nz = 0;
  double voxel_size = 1.0;
  Vec3d origin{};

  std::uint64_t voxel_count() const { return std::uint64_t(nx) * std::uint64_t(ny) * std::uint64_t(nz); }
  std::size_t index(int i, int j, int k) const {
    return std::size_t(i) + std::size_t(nx) * (std::size_t(j) + std::size_t(ny) * std::size_t(k));
  }
  int dim(int axis) const { return axis == 0 ? nx : (axis == 1 ? ny : nz); }
  Vec3d world(int i, int j, int k) const {
    return origin + Vec3d{double(i), double(j), double(k)} * voxel_size;
  }
  Vec3d to_index_space(const Vec3d& p) const { return (p - origin) / voxel_size; }
  // World box spanned by the nodes.
  BBox bounds() const;
  // p finite and inside bounds() (closed box, with a relative tolerance of 1e-9 voxels).
  bool contains(const Vec3d& p) const;
};

// Throws (see above) unless the grid has finite frame, >= 2 nodes per axis and at most
// max_voxels nodes; `where` names the caller in the error.
void validate_grid(const DenseGrid& grid, std::uint64_t max_voxels, std::string_view where);

// The grid with voxel size h whose nodes cover bounds (origin = bounds.min).
DenseGrid dense_grid_for_voxel_size(const BBox& bounds, double voxel_size,
                                    std::uint64_t max_voxels = kDefaultMaxGridVoxels);
// h = bounds.longest_side() / resolution.
DenseGrid dense_grid_for_resolution(const BBox& bounds, int resolution,
                                    std::uint64_t max_voxels = kDefaultMaxGridVoxels);

// The default box of a path or Voronoi problem: around `points` and the active voxels of
// `obstacles` (may be null), padded by `padding` x its longest side (at least 0.01).
BBox padded_problem_bounds(const std::vector<Vec3d>& points, const NarrowBand* obstacles, double padding);

}  // namespace levelset::apps
