// band_masks: a band decoded for extraction at an iso level, with per-brick inside masks, so
// that a pass which needs only the cells' classes (marching cubes' counting pass) builds them
// from bits: a cell tile's 121 rows come from 2 words of each neighbour instead of 1331
// copied values (the copies miss the cache at the tile's halo).
//
// Inputs: a band and iso (|iso| < background(), finite: check_iso first).
// Output: DecodedBand: every brick's 512 values (decode_bricks), the mask of its voxels whose
//   value lies below iso (inactive voxels by their stored sign), and which bricks can own
//   output (bricks_with_crossings, from the masks). Memory: 2 KiB + 65 bytes per brick.
// Cost: one parallel pass over the bricks (TBB). cell_masks: O(11^2) per brick.
// Threading: decode_band is parallel; cell_masks is a plain function over read-only data.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "grid/narrow_band.hpp"
#include "grid/tile.hpp"
#include "surface/surface_common.hpp"

namespace levelset::surface_detail {

struct DecodedBand {
  DecodedBricks values;
  UninitializedVector<std::uint64_t> inside;  // 8 words per brick, BrickMask layout
  std::vector<std::uint8_t> work;           // 1 where the brick can own cells or edges at iso
  std::span<const std::uint64_t, 8> inside_words(std::uint32_t b) const {
    return std::span<const std::uint64_t, 8>(inside.data() + 8 * std::size_t(b), 8);
  }
};

DecodedBand decode_band(const NarrowBand& band, double iso);

// The active and inside rows of the cell tile of around's brick (CellTile's layout) from the
// masks, then valid's cells: the same classes ValidCells::compute gives from the gathered
// tile. signs: the neighbourhood's unallocated signs (resolve_neighbor_signs over [-1, 10)).
void cell_masks(const NarrowBand& band, const DecodedBand& decoded, const Neighborhood& around,
                const NeighborSigns& signs, ValidCells& valid);

// Value minus iso at tile corner (x, y, z) in [0, 9)^3 of an allocated voxel of the
// neighbourhood (what the gathered tile would hold there).
inline double corner_value(const DecodedBand& decoded, const Neighborhood& around, int x, int y, int z, double iso) {
  const std::uint32_t nb = around[std::size_t(Neighborhood::slot(x >> 3, y >> 3, z >> 3))];
  return double(decoded.values.data[std::size_t(nb) * kBrickVoxels + std::size_t(local_index(x & 7, y & 7, z & 7))]) - iso;
}

}  // namespace levelset::surface_detail
