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
    gather_box(band, decoded, around, -CellTile::kHalo, CellTile::kDim - CellTile::kHalo, values, rows);
  tile.around = around;
}

}  // namespace levelset
