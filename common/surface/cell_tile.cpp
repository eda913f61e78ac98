#include "surface/cell_tile.hpp"

#include <span>

namespace levelset {

namespace {

std::uint32_t neighbor_at(const NarrowBand& band, std::uint32_t b, const Coord& d) {
  std::uint32_t cur = b;
  for (int a = 0; a < 3 && cur != kNoBrick; ++a)
    if (d[a] != 0) cur = band.neighbor(cur, Face(2 * a + (d[a] > 0 ? 1 : 0)));
  const int axes = (d.x != 0) + (d.y != 0) + (d.z != 0);
  if (cur == kNoBrick && axes > 1) cur = band.find_brick(band.bricks()[b].coord + d);
  return cur;
}

}  // namespace

void gather_cell_tile(const NarrowBand& band, std::uint32_t brick, CellTile& tile) {
  gather_box(band, brick, -CellTile::kHalo, CellTile::kDim - CellTile::kHalo,
             std::span<float>(tile.values.data(), CellTile::kSize), std::span<std::uint32_t>(tile.active_rows));
  for (int dz = -1; dz <= 1; ++dz)
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx)
        tile.around[CellTile::neighbor_slot(dx, dy, dz)] =
            (dx | dy | dz) == 0 ? brick : neighbor_at(band, brick, Coord{dx, dy, dz});
}

}  // namespace levelset
