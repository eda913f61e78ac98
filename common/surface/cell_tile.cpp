#include "surface/cell_tile.hpp"

#include <span>

namespace levelset {

void gather_cell_tile(const NarrowBand& band, std::uint32_t brick, CellTile& tile, std::span<const float> decoded) {
  const Neighborhood around = brick_neighborhood(band, brick);
  const std::span<float> values(tile.values.data(), CellTile::kSize);
  const std::span<std::uint32_t> rows(tile.active_rows);
  if (decoded.empty())
    gather_box(band, around, -CellTile::kHalo, CellTile::kDim - CellTile::kHalo, values, rows);
  else
    regather_cell_tile(band, around, NeighborSigns{}, tile, decoded);
  tile.around = around;
}

void regather_cell_tile(const NarrowBand& band, const Neighborhood& around, const NeighborSigns& signs,
                        CellTile& tile, std::span<const float> decoded) {
  tile.signs = signs;
  gather_box(band, decoded, around, -CellTile::kHalo, CellTile::kDim - CellTile::kHalo,
             std::span<float>(tile.values.data(), CellTile::kSize), std::span<std::uint32_t>(tile.active_rows),
             GatherRegion::Box, &tile.signs);
  tile.around = around;
}

}  // namespace levelset
