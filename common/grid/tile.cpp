#include "grid/tile.hpp"

#include <algorithm>
#include <string>

#include "core/error.hpp"

namespace levelset {

namespace {

// Neighbour brick at offset d in {-1,0,1}^3 through face links; hash only when the face
// path is broken but a diagonal brick may still exist.
std::uint32_t neighbor_at(const NarrowBand& band, std::uint32_t b, const Coord& d) {
  std::uint32_t cur = b;
  for (int a = 0; a < 3 && cur != kNoBrick; ++a) {
    if (d[a] != 0) cur = band.neighbor(cur, Face(2 * a + (d[a] > 0 ? 1 : 0)));
  }
  const int axes = (d.x != 0) + (d.y != 0) + (d.z != 0);
  if (cur == kNoBrick && axes > 1) cur = band.find_brick(band.bricks()[b].coord + d);
  return cur;
}

}  // namespace

void decode_brick(const NarrowBand& band, std::uint32_t brick, std::span<float, kBrickVoxels> out) {
  const Brick& br = band.bricks()[brick];
  const float bg = band.background();
  if (br.signs == kSignsAllOutside || br.signs == kSignsAllInside) {
    std::fill(out.begin(), out.end(), br.signs == kSignsAllInside ? -bg : bg);
  } else {
    for (int n = 0; n < kBrickVoxels; ++n) out[n] = band.stored_inside(br, n) ? -bg : bg;
  }
  const float* v = band.values().data() + br.value_offset;
  br.active.for_each_set([&](int n) { out[n] = *v++; });
}

void gather_tile(const NarrowBand& band, std::uint32_t brick, int halo, std::span<float> out) {
  if (halo < 0 || halo > kBrickDim)
    throw Error(ErrorCode::InvalidArgument, "gather_tile", "halo must be in [0, 8]");
  const TileShape shape{halo};
  if (out.size() != shape.size())
    throw Error(ErrorCode::InvalidArgument, "gather_tile", "output size does not match halo");
  const float bg = band.background();
  const Coord self = band.bricks()[brick].coord;
  alignas(64) float dense[kBrickVoxels];
  for (int dz = -1; dz <= 1; ++dz) {
    for (int dy = -1; dy <= 1; ++dy) {
      for (int dx = -1; dx <= 1; ++dx) {
        const Coord d{dx, dy, dz};
        // Local range of the neighbour that falls into the tile, per axis.
        int lo[3], hi[3];
        bool empty = false;
        for (int a = 0; a < 3; ++a) {
          lo[a] = d[a] < 0 ? kBrickDim - halo : 0;
          hi[a] = d[a] > 0 ? halo : kBrickDim;
          if (d[a] != 0 && halo == 0) empty = true;
        }
        if (empty) continue;
        const std::uint32_t nb = (dx | dy | dz) == 0 ? brick : neighbor_at(band, brick, d);
        if (nb == kNoBrick) {
          // Unallocated: one sign for the whole brick (band invariant).
          const Coord probe = brick_origin(self + d) + Coord{lo[0], lo[1], lo[2]};
          const float v = band.is_inside_unallocated(probe) ? -bg : bg;
          for (int z = lo[2]; z < hi[2]; ++z)
            for (int y = lo[1]; y < hi[1]; ++y)
              for (int x = lo[0]; x < hi[0]; ++x)
                out[shape.index(x + d.x * kBrickDim, y + d.y * kBrickDim, z + d.z * kBrickDim)] = v;
          continue;
        }
        if (nb == brick) {
          decode_brick(band, nb, std::span<float, kBrickVoxels>(dense, kBrickVoxels));
          for (int z = 0; z < kBrickDim; ++z)
            for (int y = 0; y < kBrickDim; ++y)
              std::copy_n(dense + local_index(0, y, z), kBrickDim, &out[shape.index(0, y, z)]);
          continue;
        }
        // Halo slab of a neighbour: only the voxels needed, one popcount each.
        const Brick& br = band.bricks()[nb];
        const float* vals = band.values().data() + br.value_offset;
        for (int z = lo[2]; z < hi[2]; ++z)
          for (int y = lo[1]; y < hi[1]; ++y)
            for (int x = lo[0]; x < hi[0]; ++x) {
              const int n = local_index(x, y, z);
              out[shape.index(x + d.x * kBrickDim, y + d.y * kBrickDim, z + d.z * kBrickDim)] =
                  br.active.test(n) ? vals[br.slot(n)] : (band.stored_inside(br, n) ? -bg : bg);
            }
      }
    }
  }
}

void scatter_active(NarrowBand& band, std::uint32_t brick, int halo, std::span<const float> tile) {
  const TileShape shape{halo};
  if (tile.size() != shape.size())
    throw Error(ErrorCode::InvalidArgument, "scatter_active", "tile size does not match halo");
  band.update_active_in_brick(brick, [&](int n, float) {
    const Coord l = local_coord(n);
    return tile[shape.index(l.x, l.y, l.z)];
  });
}

}  // namespace levelset
