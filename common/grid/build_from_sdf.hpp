// build_from_sdf: sample a signed distance function into a NarrowBand.
//
// Inputs: sdf(p) -> signed distance at world point p (negative inside), 1-Lipschitz with
//   |sdf(p)| <= true distance (exact SDFs qualify); the world bounds of the zero level set;
//   the grid frame (voxel size h, origin, half-width W voxels).
// Output: a band holding sdf at every voxel with |sdf| <= W*h, the inside bit of every voxel
//   in allocated bricks, and far_inside = false (the shape is bounded).
// Method: octree-style descent over brick blocks; a block is skipped when
//   |sdf(center)| > half-diagonal + W*h, so cost is O(surface bricks * 512) SDF calls plus
//   O(surface bricks * log(extent)) coarse calls.
// Threading: leaf bricks are sampled in parallel (TBB); the result is identical for any
//   thread count. Progress: fraction of leaf bricks done; cancellable between batches.
// Errors: Error{NonFinite} if sdf returns NaN/Inf; Error{LimitExceeded} when the domain
//   exceeds the index range or options.max_voxels (the voxel budget).
#pragma once

#include <cstdint>
#include <functional>

#include "core/bbox.hpp"
#include "core/progress.hpp"
#include "grid/narrow_band.hpp"

namespace levelset {

struct SdfBuildOptions {
  GridFrame frame;
  // Budget on the dense index box that is searched ((extent/h)^3 voxels); guards against
  // absurd voxel sizes. 2^40 ~ a 10240^3 domain.
  std::uint64_t max_domain_voxels = std::uint64_t{1} << 40;
  ProgressHook progress;
};

struct SdfBuildResult {
  NarrowBand band;
  std::uint64_t leaf_bricks_sampled = 0;  // bricks whose 512 voxels were evaluated
  std::uint64_t sdf_calls = 0;
  double seconds = 0.0;
};

using SdfFunction = std::function<double(const Vec3d&)>;

SdfBuildResult build_from_sdf(const SdfFunction& sdf, const BBox& surface_bounds,
                              const SdfBuildOptions& options);

// The frame used by "--resolution R": R voxels along the longest side of bounds padded by
// the band (W voxels each side), origin at the padded minimum corner.
// Throws Error{InvalidArgument} unless R > 2W + 1 and bounds are non-empty and finite.
GridFrame frame_for_resolution(const BBox& bounds, int resolution, double half_width);

}  // namespace levelset
