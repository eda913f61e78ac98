#include "surface/cell_tile.hpp"

#include <algorithm>
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
  constexpr int H = CellTile::kHalo;
  gather_tile(band, brick, H, std::span<float>(tile.values));
  std::fill(tile.active.begin(), tile.active.end(), std::uint8_t{0});
  for (int dz = -1; dz <= 1; ++dz)
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
        const Coord d{dx, dy, dz};
        const std::uint32_t nb = (dx | dy | dz) == 0 ? brick : neighbor_at(band, brick, d);
        tile.around[CellTile::neighbor_slot(dx, dy, dz)] = nb;
        if (nb == kNoBrick) continue;
        int lo[3], hi[3];
        for (int a = 0; a < 3; ++a) {
          lo[a] = d[a] < 0 ? kBrickDim - H : 0;
          hi[a] = d[a] > 0 ? H : kBrickDim;
        }
        const BrickMask& m = band.bricks()[nb].active;
        for (int z = lo[2]; z < hi[2]; ++z)
          for (int y = lo[1]; y < hi[1]; ++y)
            for (int x = lo[0]; x < hi[0]; ++x)
              tile.active[CellTile::index(x + dx * kBrickDim, y + dy * kBrickDim, z + dz * kBrickDim)] =
                  std::uint8_t(m.test(local_index(x, y, z)));
      }
}

}  // namespace levelset
