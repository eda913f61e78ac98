// voxel_winding_numbers: the winding numbers of some voxels of one brick in one tree traversal.
//
// Inputs: the tree, the grid frame (voxel centres at origin + index * h), the brick's voxel
// origin (brick_origin), brick-local voxel indices (local_index; at most kBrickVoxels), beta.
// Output: out[i] = winding_number(tree, centre of voxels[i], beta), bit for bit (it calls
// winding_numbers). Cost: one batch traversal. Threading: pure. Errors: none.
#pragma once

#include <array>
#include <span>

#include "distance/winding_number.hpp"
#include "grid/narrow_band.hpp"

namespace levelset {

inline void voxel_winding_numbers(const WindingNumberTree& tree, const GridFrame& frame, const Coord& origin,
                                  std::span<const int> voxels, double beta, std::span<double> out) {
  std::array<Vec3d, kBrickVoxels> points;
  for (std::size_t i = 0; i < voxels.size(); ++i) {
    const Coord g = origin + local_coord(voxels[i]);
    points[i] = frame.origin + Vec3d{double(g.x), double(g.y), double(g.z)} * frame.voxel_size;
  }
  winding_numbers(tree, std::span(points.data(), voxels.size()), beta, out.first(voxels.size()));
}

}  // namespace levelset
