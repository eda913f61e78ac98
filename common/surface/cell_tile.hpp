// CellTile: one brick's values and active flags with the halo the surface extractors need:
// the box [-1, 10)^3 of brick-local voxels (cells [-1, 8)^3 with their corners, and central
// differences at the corners [0, 9)^3).
//
// Inputs: a band and a brick index. Output: dense 11^3 values (grid/tile.hpp gather_box layout,
// +-background outside the band; 4 floats of padding at the end for vector loads), active row
// bitmasks (bit x + kHalo of row (y, z) where the band stores voxel (x, y, z)), and the indices
// of the brick and its 26 neighbours (around[Neighborhood::slot(d)] for d in {-1,0,1}^3; kNoBrick
// where unallocated). Cost: O(11^3) plus up to 26 neighbour resolutions (face links, a hash
// lookup only for a diagonal brick whose face path is unallocated). Threading: one tile per
// thread; the band is read only.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "grid/tile.hpp"

namespace levelset {

struct CellTile {
  static constexpr int kHalo = 1;  // below the brick; 2 above
  static constexpr int kDim = kBrickDim + 3;
  static constexpr int kSize = kDim * kDim * kDim;
  static constexpr int kPadding = 4;
  static constexpr int index(int x, int y, int z) {
    return (x + kHalo) + kDim * ((y + kHalo) + kDim * (z + kHalo));
  }
  std::vector<float> values = std::vector<float>(kSize + kPadding);
  static constexpr int row(int y, int z) { return (y + kHalo) + kDim * (z + kHalo); }
  std::array<std::uint32_t, kDim * kDim> active_rows{};
  Neighborhood around{};
  NeighborSigns signs{};  // of around's unallocated bricks (with decoded only)
};

// decoded: decode_bricks(band) (the tile is then gathered by row copies) or empty.
void gather_cell_tile(const NarrowBand& band, std::uint32_t brick, CellTile& tile, std::span<const float> decoded = {});
// Gathers the same brick again from decoded, with the neighbourhood and the signs an earlier
// gather of it left in a tile (no neighbour search).
void regather_cell_tile(const NarrowBand& band, const Neighborhood& around, const NeighborSigns& signs,
                        CellTile& tile, std::span<const float> decoded);

}  // namespace levelset
