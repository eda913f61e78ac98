// BrickSet: a sorted set of bricks, for band-wide voxel fields stored 512 per brick (voxel
// index = slot * 512 + local index).
//
// dilate_bricks(bricks, reach): every brick within `reach` bricks (Chebyshev) of a given one,
//   sorted by key. Cost: O(n reach^3) keys and one parallel sort. Threading: TBB,
//   deterministic.
// slot_of(brick): the brick's slot or kNoBrick (binary search).
#pragma once

#include <cstdint>
#include <vector>

#include "grid/coord.hpp"

namespace levelset {

struct BrickSet {
  std::vector<Coord> bricks;        // sorted by brick_key
  std::vector<std::uint64_t> keys;  // their keys

  std::uint32_t slot_of(const Coord& brick) const;
};

BrickSet dilate_bricks(const std::vector<Coord>& bricks, int reach);

}  // namespace levelset
