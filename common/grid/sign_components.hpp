// sign_components: the connected components of a band's inside and outside voxel sets.
//
// Inputs: a NarrowBand (any voxel's sign: active voxels by value, the others by the band's
//   inside masks and far_inside); SignComponentsOptions.
// Output: SignComponentsResult over the band's active index box grown by one voxel (so the
//   box's outer layer holds only far voxels): a dense label per voxel (x fastest) and per
//   label its sign, size, whether it touches the box's faces (for a band whose far field is
//   outside, the outside component touching them is the exterior), whether all its voxels
//   are active (a component with band-interior voxels cannot be rewritten through values
//   alone), and its front voxels (those with a face neighbour of the other sign), in
//   index order.
// Connectivity: 6 (faces) or 26 (faces, edges, corners) per sign; the default pair (inside
//   26, outside 6) is a consistent one: its components are those of the surface the marching
//   cubes draw, up to the ambiguous faces and cubes they decide by value. 6 for both finds
//   every piece that a decision by value may separate (each component then is a candidate).
// Cost: O(box voxels) time; 5 bytes per box voxel plus the flood fill's stack (4 bytes per
//   voxel of the largest component at most). Threading: serial flood fills after a
//   TBB sign pass; deterministic.
// Errors: Error{InvalidArgument} for a connectivity other than 6 or 26 or max_voxels over 2^32; Error{LimitExceeded} when the box exceeds options.max_voxels; Error{Cancelled}
//   through progress.
#pragma once

#include <cstdint>
#include <vector>

#include "core/progress.hpp"
#include "grid/coord.hpp"
#include "grid/narrow_band.hpp"

namespace levelset {

struct SignComponentsOptions {
  int inside_connectivity = 26;  // 6 or 26
  int outside_connectivity = 6;  // 6 or 26
  std::uint64_t max_voxels = std::uint64_t(1) << 27;
  ProgressHook progress;
};

struct SignComponent {
  bool inside = false;
  bool touches_box = false;     // reaches the box's outer layer
  bool all_active = true;       // every voxel is an active band voxel
  std::uint64_t voxels = 0;
  std::vector<Coord> front;     // voxels with a face neighbour of the other sign
};

struct SignComponentsResult {
  IndexBox box;                       // active bounds grown by one voxel
  std::vector<std::int32_t> label;    // per box voxel (x fastest): index into components
  std::vector<SignComponent> components;
  // Index of c in `label`; c must lie in box.
  std::size_t index_of(const Coord& c) const {
    const std::size_t nx = std::size_t(box.max.x - box.min.x + 1), ny = std::size_t(box.max.y - box.min.y + 1);
    return (std::size_t(c.z - box.min.z) * ny + std::size_t(c.y - box.min.y)) * nx + std::size_t(c.x - box.min.x);
  }
};

SignComponentsResult sign_components(const NarrowBand& band, const SignComponentsOptions& options = {});

}  // namespace levelset
