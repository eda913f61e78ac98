#include "grid/tile.hpp"

#include <algorithm>
#include <bit>
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
  gather_tile(band, brick, halo, out, {});
}

void gather_tile(const NarrowBand& band, std::uint32_t brick, int halo, std::span<float> out,
                 std::span<std::uint32_t> active_rows) {
  if (halo < 0 || halo > kBrickDim)
    throw Error(ErrorCode::InvalidArgument, "gather_tile", "halo must be in [0, 8]");
  const TileShape shape{halo};
  const int dim = shape.dim();
  if (out.size() != shape.size())
    throw Error(ErrorCode::InvalidArgument, "gather_tile", "output size does not match halo");
  const bool rows = !active_rows.empty();
  if (rows && active_rows.size() != std::size_t(dim) * std::size_t(dim))
    throw Error(ErrorCode::InvalidArgument, "gather_tile", "active_rows size must be dim^2");
  if (rows) std::fill(active_rows.begin(), active_rows.end(), 0u);
  const float bg = band.background();
  const Coord self = band.bricks()[brick].coord;
  const float* all_values = band.values().data();
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
        const int width = hi[0] - lo[0];
        if (nb == kNoBrick) {
          // Unallocated: one sign for the whole brick (band invariant).
          const Coord probe = brick_origin(self + d) + Coord{lo[0], lo[1], lo[2]};
          const float v = band.is_inside_unallocated(probe) ? -bg : bg;
          for (int z = lo[2]; z < hi[2]; ++z)
            for (int y = lo[1]; y < hi[1]; ++y)
              std::fill_n(&out[shape.index(lo[0] + dx * kBrickDim, y + dy * kBrickDim, z + dz * kBrickDim)], width, v);
          continue;
        }
        // Row by row: a row of a brick is one byte of its masks, and its active values are
        // contiguous in the packed storage.
        const Brick& br = band.bricks()[nb];
        const float* vals = all_values + br.value_offset;
        const std::uint32_t xmask = ((1u << hi[0]) - 1u) & ~((1u << lo[0]) - 1u);
        const int shift = lo[0] + dx * kBrickDim + halo;  // tile bit of local x = lo[0]
        for (int z = lo[2]; z < hi[2]; ++z) {
          const std::uint64_t act_word = br.active.words[std::size_t(z)];
          const std::uint64_t ins_word = band.stored_inside_word(br, z);
          const int rank_z = br.rank_base(z);
          for (int y = lo[1]; y < hi[1]; ++y) {
            const int bit0 = 8 * y;
            const std::uint32_t act = std::uint32_t(act_word >> bit0) & 0xffu;
            const std::uint32_t ins = std::uint32_t(ins_word >> bit0) & 0xffu;
            const std::size_t row = shape.index(0, y + dy * kBrickDim, z + dz * kBrickDim) - std::size_t(halo);
            float* o = &out[row + std::size_t(dx * kBrickDim + halo)];
            for (int x = lo[0]; x < hi[0]; ++x) o[x] = ((ins >> x) & 1u) ? -bg : bg;
            const std::uint32_t take = act & xmask;
            if (take != 0) {
              int k = rank_z + std::popcount(act_word & ((std::uint64_t{1} << bit0) - 1)) +
                      std::popcount(act & ((1u << lo[0]) - 1u));
              for (std::uint32_t b = take; b != 0; b &= b - 1) o[std::countr_zero(b)] = vals[k++];
            }
            if (rows) active_rows[row / std::size_t(dim)] |= (take >> lo[0]) << shift;
          }
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
