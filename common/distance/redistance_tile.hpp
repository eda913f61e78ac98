// Dense tile geometry for redistance()'s per-brick kernels: a brick plus a halo of `Halo`
// voxels (1 for the interface set-up and the first-order sweep, 2 for the second-order
// sweep), laid out like grid/tile.hpp (x fastest, tile index of local voxel (x,y,z) =
// (x+Halo) + dim*((y+Halo) + dim*(z+Halo)), dim = 8 + 2*Halo).
//
// TileGeom<Halo>: compile-time strides and index, plus per-voxel tables: tile_of[n] = the
//   tile index of local voxel n, faces[n] bit f = n lies within Halo voxels of face f (Face
//   order: -x, +x, -y, +y, -z, +z).
// for_each_halo_voxel<Halo>(nbr, f): visits the face neighbours' voxels that fill the halo.
// Cost: tables built at compile time (kTileGeom<Halo>; kGeom1, kGeom2). Threading: constant data.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

#include "grid/coord.hpp"

namespace levelset::detail {

template <int Halo>
struct TileGeom {
  static constexpr int kDim = kBrickDim + 2 * Halo;
  static constexpr int kVoxels = kDim * kDim * kDim;
  static constexpr int kStride[3] = {1, kDim, kDim * kDim};
  static constexpr int index(int x, int y, int z) { return (x + Halo) + kDim * ((y + Halo) + kDim * (z + Halo)); }
  std::array<std::uint16_t, kBrickVoxels> tile_of{};
  std::array<std::uint8_t, kBrickVoxels> faces{};  // bit f: within Halo voxels of face f
  constexpr TileGeom() {
    for (int n = 0; n < kBrickVoxels; ++n) {
      const int c[3] = {n & 7, (n >> 3) & 7, n >> 6};
      tile_of[n] = std::uint16_t(index(c[0], c[1], c[2]));
      for (int a = 0; a < 3; ++a) {
        if (c[a] < Halo) faces[n] |= std::uint8_t(1u << (2 * a));
        if (c[a] >= kBrickDim - Halo) faces[n] |= std::uint8_t(1u << (2 * a + 1));
      }
    }
  }
};
template <int Halo>
inline constexpr TileGeom<Halo> kTileGeom{};

// f(neighbour brick, its local voxel index, tile index) for every voxel of the `Halo` layers
// that the face neighbours nbr (Face order, kNoBrick: none) contribute to the tile.
template <int Halo, typename F>
void for_each_halo_voxel(const std::array<std::uint32_t, 6>& nbr, F&& f) {
  for (int face = 0; face < 6; ++face) {
    const std::uint32_t nb = nbr[std::size_t(face)];
    if (nb == kNoBrick) continue;
    const int axis = face >> 1, u = axis == 0 ? 1 : 0, v = axis == 2 ? 1 : 2;
    for (int layer = 0; layer < Halo; ++layer) {
      const int mine = (face & 1) ? kBrickDim + layer : -1 - layer;  // tile coordinate on axis
      const int theirs = (face & 1) ? layer : kBrickDim - 1 - layer;
      for (int j = 0; j < kBrickDim; ++j)
        for (int i = 0; i < kBrickDim; ++i) {
          int c[3], t[3];
          c[axis] = theirs;
          t[axis] = mine;
          c[u] = t[u] = i;
          c[v] = t[v] = j;
          f(nb, local_index(c[0], c[1], c[2]), TileGeom<Halo>::index(t[0], t[1], t[2]));
        }
    }
  }
}
inline constexpr const TileGeom<1>& kGeom1 = kTileGeom<1>;
inline constexpr const TileGeom<2>& kGeom2 = kTileGeom<2>;

}  // namespace levelset::detail
