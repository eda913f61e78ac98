#include "surface/cell_tile.hpp"

#include <array>
#include <cstring>
#include <span>

#include "core/error.hpp"

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

namespace {

// Per tile row index t in [0, 11) (local coordinate t - 1): the brick offset along that axis
// and the local coordinate inside that brick.
constexpr std::array<int, CellTile::kDim> kRowBrick = {-1, 0, 0, 0, 0, 0, 0, 0, 0, 1, 1};
constexpr std::array<int, CellTile::kDim> kRowLocal = {7, 0, 1, 2, 3, 4, 5, 6, 7, 0, 1};

}  // namespace

// The box [-1, 10)^3 row by row: each tile row is voxel 7 of the -x neighbour's row, the
// brick's own 8 (one vector move) and voxels 0, 1 of the +x neighbour's, with the three
// sources picked from a 27-entry table (an unallocated neighbour reads a row of its sign's
// value with stride 0). Equal to gather_box over decoded bricks (which handles any box and
// resolves each neighbour range's layout per call: ~14 % of marching cubes).
void regather_cell_tile(const NarrowBand& band, const Neighborhood& around, const NeighborSigns& signs,
                        CellTile& tile, std::span<const float> decoded) {
  if (decoded.size() != band.brick_count() * std::size_t(kBrickVoxels))
    throw Error(ErrorCode::InvalidArgument, "regather_cell_tile", "decoded bricks do not match the band");
  tile.signs = signs;
  std::uint32_t unallocated = 0;
  for (int k = 0; k < 27; ++k)
    if (around[std::size_t(k)] == kNoBrick) unallocated |= 1u << k;
  if ((unallocated & ~tile.signs.known) != 0)
    tile.signs = resolve_neighbor_signs(band, around, -CellTile::kHalo, CellTile::kDim - CellTile::kHalo);
  const float bg = band.background();
  const std::array<float, kBrickDim> fill[2] = {{bg, bg, bg, bg, bg, bg, bg, bg}, {-bg, -bg, -bg, -bg, -bg, -bg, -bg, -bg}};
  static constexpr std::array<std::uint64_t, kBrickDim> kNoActive{};
  const float* base[27];
  int step[27];  // floats per (y + 8 z): 8, or 0 for a fill row
  const std::uint64_t* active[27];
  for (int k = 0; k < 27; ++k) {
    const std::uint32_t nb = around[std::size_t(k)];
    if (nb == kNoBrick) {
      base[k] = fill[(tile.signs.inside >> k) & 1u].data();
      step[k] = 0;
      active[k] = kNoActive.data();
    } else {
      base[k] = decoded.data() + std::size_t(nb) * kBrickVoxels;
      step[k] = kBrickDim;
      active[k] = band.bricks()[nb].active.words.data();
    }
  }
  float* out = tile.values.data();
  for (int tz = 0; tz < CellTile::kDim; ++tz) {
    const int bz = kRowBrick[std::size_t(tz)], lz = kRowLocal[std::size_t(tz)];
    for (int ty = 0; ty < CellTile::kDim; ++ty, out += CellTile::kDim) {
      const int by = kRowBrick[std::size_t(ty)], ly = kRowLocal[std::size_t(ty)];
      const int k = Neighborhood::slot(0, by, bz), row = ly + kBrickDim * lz;
      const float* lo = base[k - 1] + step[k - 1] * row;
      const float* mid = base[k] + step[k] * row;
      const float* hi = base[k + 1] + step[k + 1] * row;
      out[0] = lo[7];
      std::array<float, kBrickDim> centre;
      std::memcpy(centre.data(), mid, sizeof centre);
      std::memcpy(out + 1, centre.data(), sizeof centre);
      out[9] = hi[0];
      out[10] = hi[1];
      auto row_bits = [&](int slot) { return std::uint32_t(active[slot][lz] >> (8 * ly)) & 0xffu; };
      tile.active_rows[std::size_t(ty + CellTile::kDim * tz)] =
          (row_bits(k - 1) >> 7) | (row_bits(k) << 1) | ((row_bits(k + 1) & 3u) << 9);
    }
  }
  tile.around = around;
}

}  // namespace levelset
