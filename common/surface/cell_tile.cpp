#include "surface/cell_tile.hpp"

#include <span>

namespace levelset {

void gather_cell_tile(const NarrowBand& band, std::uint32_t brick, CellTile& tile) {
  const Neighborhood around = brick_neighborhood(band, brick);
  gather_box(band, around, -CellTile::kHalo, CellTile::kDim - CellTile::kHalo,
             std::span<float>(tile.values.data(), CellTile::kSize), std::span<std::uint32_t>(tile.active_rows));
  tile.around = around;
}

}  // namespace levelset
