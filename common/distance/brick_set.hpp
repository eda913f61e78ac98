// BrickSet: a sorted set of bricks with each brick's 27-neighbourhood as slots, for band-wide
// voxel fields stored 512 per brick (voxel id = slot * 512 + local index).
//
// dilate_bricks(bricks, reach): every brick within `reach` bricks (Chebyshev) of a given one,
//   sorted by key, with its neighbour slots (kNoBrick outside the set). Cost: O(n reach^3) keys
//   and one parallel sort. Threading: TBB, deterministic.
// neighbour_id(set, id, d): the voxel id at offset d (each component -1, 0, 1) from voxel id,
//   or kNoVoxel when its brick is not in the set.
// slot_of(brick): the brick's slot or kNoBrick (binary search).
#pragma once

#include <cstdint>
#include <vector>

#include "grid/coord.hpp"

namespace levelset {

inline constexpr std::uint64_t kNoVoxel = ~std::uint64_t{0};

struct BrickSet {
  std::vector<Coord> bricks;              // sorted by brick_key
  std::vector<std::uint64_t> keys;        // their keys
  std::vector<std::uint32_t> neighbours;  // 27 per brick: (dx+1) + 3 (dy+1) + 9 (dz+1)

  std::uint32_t slot_of(const Coord& brick) const;
};

BrickSet dilate_bricks(const std::vector<Coord>& bricks, int reach);

inline std::uint64_t neighbour_id(const BrickSet& set, std::uint64_t id, const Coord& d) {
  const std::uint64_t slot = id / kBrickVoxels;
  const Coord l = local_coord(int(id % kBrickVoxels));
  const int x = l.x + d.x, y = l.y + d.y, z = l.z + d.z;
  const int bx = x < 0 ? 0 : (x >= kBrickDim ? 2 : 1);
  const int by = y < 0 ? 0 : (y >= kBrickDim ? 2 : 1);
  const int bz = z < 0 ? 0 : (z >= kBrickDim ? 2 : 1);
  const std::uint32_t nslot = set.neighbours[slot * 27 + std::uint64_t(bx + 3 * by + 9 * bz)];
  if (nslot == kNoBrick) return kNoVoxel;
  return std::uint64_t(nslot) * kBrickVoxels + std::uint64_t(local_index(x & 7, y & 7, z & 7));
}

}  // namespace levelset
