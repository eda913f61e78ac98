#include "apps/dense_grid.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "core/error.hpp"

namespace levelset::apps {

namespace {

constexpr int kMaxAxisNodes = 1 << 30;

}  // namespace

BBox DenseGrid::bounds() const {
  BBox b;
  b.extend(origin);
  b.extend(world(nx - 1, ny - 1, nz - 1));
  return b;
}

bool DenseGrid::contains(const Vec3d& p) const {
  if (!isfinite(p)) return false;
  const Vec3d q = to_index_space(p);
  constexpr double tol = 1e-9;
  for (int a = 0; a < 3; ++a)
    if (!(q[a] >= -tol && q[a] <= double(dim(a) - 1) + tol)) return false;
  return true;
}

void validate_grid(const DenseGrid& grid, std::uint64_t max_voxels, std::string_view where) {
  const std::string at(where);
  if (!(std::isfinite(grid.voxel_size) && grid.voxel_size > 0.0))
    throw Error(ErrorCode::InvalidArgument, at, "voxel size must be finite and > 0");
  if (!isfinite(grid.origin)) throw Error(ErrorCode::NonFinite, at, "grid origin is not finite");
  for (int a = 0; a < 3; ++a) {
    if (grid.dim(a) < 2)
      throw Error(ErrorCode::InvalidArgument, at, "the grid needs at least 2 nodes per axis");
    if (grid.dim(a) > kMaxAxisNodes)
      throw Error(ErrorCode::LimitExceeded, at, "more than 2^30 nodes along one axis");
  }
  if (!isfinite(grid.world(grid.nx - 1, grid.ny - 1, grid.nz - 1)))
    throw Error(ErrorCode::NonFinite, at, "grid extent is not finite");
  if (grid.voxel_count() > max_voxels)
    throw Error(ErrorCode::LimitExceeded, at,
                std::to_string(grid.voxel_count()) + " nodes exceed the limit of " + std::to_string(max_voxels));
}

DenseGrid dense_grid_for_voxel_size(const BBox& bounds, double voxel_size, std::uint64_t max_voxels) {
  if (bounds.empty() || !isfinite(bounds.min) || !isfinite(bounds.max))
    throw Error(ErrorCode::InvalidArgument, "dense grid", "bounds are empty or not finite");
  if (!(std::isfinite(voxel_size) && voxel_size > 0.0))
    throw Error(ErrorCode::InvalidArgument, "dense grid", "voxel size must be finite and > 0");
  DenseGrid grid;
  grid.voxel_size = voxel_size;
  grid.origin = bounds.min;
  const Vec3d extent = bounds.extent();
  for (int a = 0; a < 3; ++a) {
    // Nodes to cover the extent; the small slack keeps exact multiples from gaining a node.
    const double cells = std::ceil(extent[a] / voxel_size - 1e-9);
    if (!(cells < double(kMaxAxisNodes)))
      throw Error(ErrorCode::LimitExceeded, "dense grid", "more than 2^30 nodes along one axis");
    const int n = std::max(2, int(cells) + 1);
    (a == 0 ? grid.nx : (a == 1 ? grid.ny : grid.nz)) = n;
  }
  validate_grid(grid, max_voxels, "dense grid");
  return grid;
}

DenseGrid dense_grid_for_resolution(const BBox& bounds, int resolution, std::uint64_t max_voxels) {
  if (resolution < 2) throw Error(ErrorCode::InvalidArgument, "dense grid", "resolution must be >= 2");
  if (bounds.empty() || !isfinite(bounds.min) || !isfinite(bounds.max) || !(bounds.longest_side() > 0.0))
    throw Error(ErrorCode::InvalidArgument, "dense grid", "bounds are empty, flat or not finite");
  return dense_grid_for_voxel_size(bounds, bounds.longest_side() / resolution, max_voxels);
}

BBox padded_problem_bounds(const std::vector<Vec3d>& points, const NarrowBand* obstacles, double padding) {
  BBox box;
  for (const Vec3d& p : points) box.extend(p);
  if (obstacles != nullptr && obstacles->active_voxel_count() > 0) {
    const BBox bb = obstacles->active_world_bounds();
    box.extend(bb.min);
    box.extend(bb.max);
  }
  const double pad = std::max(padding * box.longest_side(), 0.01);
  box.min -= Vec3d{pad, pad, pad};
  box.max += Vec3d{pad, pad, pad};
  return box;
}

}  // namespace levelset::apps
