// The computational domain of redistance() (redistance.hpp): the bricks to compute, with
// dense unsigned distances, and its conversion back into a NarrowBand.
//
// build_domain(in, grow, progress)
//   Inputs: the input band; grow >= 0 = voxels by which its active voxels are dilated
//   (26-neighbourhood: one voxel along x, y, z per step), allocating the bricks that the
//   dilation reaches; progress is checked after each step.
//   Output: bricks sorted by brick_key with face links, the input brick of each (kNoBrick for
//   new ones; the same index when grow = 0), the domain mask (the dilated active voxels), the
//   input's sign of every voxel (new bricks: one sign per x-row, NarrowBand's row rule), no
//   fixed voxels and dist = kInf everywhere.
//   Errors: Error{LimitExceeded} when growing leaves the index range or the domain exceeds
//   kMaxBricks bricks; Error{Cancelled} from progress.
// assemble_band(in, w, frame)
//   Output: a band with `frame` holding the fixed voxels and the domain voxels with
//   dist <= frame.half_width, valued dist * h and signed by w.inside (inside voxels strictly
//   negative). Bricks left without active voxels are dropped, except one per brick row
//   whose sign differs from in.far_inside() and would otherwise be lost.
// Cost: O(grow * bricks log bricks) for the dilation, O(domain voxels) otherwise; memory 4
//   bytes per voxel of the domain's bricks plus four masks per brick.
// Threading: TBB, per brick in parallel; results do not depend on the thread count.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "core/progress.hpp"
#include "core/uninitialized_vector.hpp"
#include "distance/eikonal_update.hpp"
#include "grid/narrow_band.hpp"

namespace levelset::detail {

inline constexpr std::size_t kMaxBricks = std::size_t{1} << 23;  // voxel ids b*512+n fit in 32 bits

// Bricks sorted by key, dense unsigned distances in voxels.
struct RedistanceDomain {
  std::vector<Coord> coords;
  std::vector<std::array<std::uint32_t, 6>> nbr;  // face neighbours, kNoBrick if none
  std::vector<std::uint32_t> source;              // input brick or kNoBrick
  std::vector<BrickMask> domain;                  // voxels to compute
  std::vector<BrickMask> fixed;                   // interface voxels (never updated)
  std::vector<BrickMask> inside;                  // input sign of every voxel
  UninitializedVector<float> dist;                // 512 per brick; +inf = unknown (filled in parallel)
  // Optional (march only): 512 per brick, a free voxel's value is accepted only up to its cap
  // (voxels; beyond it the voxel stays unknown and passes nothing on). Empty: the limit alone.
  UninitializedVector<float> cap;  // (filled in parallel)

  std::size_t size() const { return coords.size(); }
  float* values(std::uint32_t b) { return dist.data() + std::size_t(b) * kBrickVoxels; }
  const float* values(std::uint32_t b) const { return dist.data() + std::size_t(b) * kBrickVoxels; }
};

RedistanceDomain build_domain(const NarrowBand& in, int grow, const ProgressHook& progress);

NarrowBand assemble_band(const NarrowBand& in, const RedistanceDomain& w, const GridFrame& frame);

}  // namespace levelset::detail
