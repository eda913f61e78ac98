#include "surface/band_masks.hpp"

#include <array>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#if defined(__SSE2__)
#include <immintrin.h>
#endif


namespace levelset::surface_detail {

namespace {

// Bit i of the result: v[i] < below, for 64 values.
std::uint64_t below_bits(const float* v, float below) {
  std::uint64_t bits = 0;
#if defined(__SSE2__)
  const __m128 lim = _mm_set1_ps(below);
  for (int i = 0; i < 64; i += 4)
    bits |= std::uint64_t(_mm_movemask_ps(_mm_cmplt_ps(_mm_loadu_ps(v + i), lim))) << i;
#else
  for (int i = 0; i < 64; ++i) bits |= std::uint64_t(v[i] < below) << i;
#endif
  return bits;
}

}  // namespace

DecodedBand decode_band(const NarrowBand& band, double iso) {
  DecodedBand out;
  out.values = decode_bricks(band);
  const std::size_t nb = band.brick_count();
  resize_with_huge_pages(out.inside, 8 * nb);  // written below
  // Bit 0: some active value < iso; bit 1: some active value >= iso.
  std::vector<std::uint8_t> sides(nb);
  const float below = ValidCells::float_below(iso);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, nb, 256), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t b = r.begin(); b != r.end(); ++b) {
      const BrickMask& active = band.bricks()[b].active;
      std::uint64_t in = 0, out_side = 0;
      for (int w = 0; w < 8; ++w) {
        const std::uint64_t bits = below_bits(out.values.data.data() + b * kBrickVoxels + 64 * std::size_t(w), below);
        out.inside[8 * b + std::size_t(w)] = bits;
        in |= bits & active.words[std::size_t(w)];
        out_side |= ~bits & active.words[std::size_t(w)];
      }
      sides[b] = std::uint8_t((in != 0 ? 1 : 0) | (out_side != 0 ? 2 : 0));
    }
  });
  out.work = bricks_with_crossings(band, sides);
  return out;
}

void cell_masks(const NarrowBand& band, const DecodedBand& decoded, const Neighborhood& around,
                const NeighborSigns& signs, ValidCells& valid) {
  constexpr int kH = CellTile::kHalo;
  // Each neighbour's mask words (an unallocated one: none active, all on its sign's side).
  static constexpr std::array<std::uint64_t, 8> kNone{}, kAll{~0ull, ~0ull, ~0ull, ~0ull, ~0ull, ~0ull, ~0ull, ~0ull};
  const std::uint64_t* active_words[27];
  const std::uint64_t* inside_words[27];
  for (int k = 0; k < 27; ++k) {
    const std::uint32_t nb = around[std::size_t(k)];
    if (nb == kNoBrick) {
      active_words[k] = kNone.data();
      inside_words[k] = ((signs.inside >> k) & 1u) ? kAll.data() : kNone.data();
    } else {
      active_words[k] = band.bricks()[nb].active.words.data();
      inside_words[k] = decoded.inside_words(nb).data();
    }
  }
  for (int z = -kH; z < CellTile::kDim - kH; ++z) {
    const int dz = z < 0 ? -1 : (z >= kBrickDim ? 1 : 0), lz = z - kBrickDim * dz;
    for (int y = -kH; y < CellTile::kDim - kH; ++y) {
      const int dy = y < 0 ? -1 : (y >= kBrickDim ? 1 : 0), shift = 8 * (y - kBrickDim * dy);
      const int k = Neighborhood::slot(0, dy, dz);  // the x neighbours are k - 1 and k + 1
      // The row's 8 voxels in each x neighbour: tile bit x + kHalo takes x = -1 from the lower
      // neighbour's last voxel, [0, 8) from the brick, 8 and 9 from the upper neighbour's first two.
      auto row = [&](const std::uint64_t* const* words) {
        const std::uint32_t lower = std::uint32_t(words[k - 1][lz] >> shift) & 0xffu;
        const std::uint32_t mid = std::uint32_t(words[k][lz] >> shift) & 0xffu;
        const std::uint32_t upper = std::uint32_t(words[k + 1][lz] >> shift) & 0xffu;
        return (lower >> 7) | (mid << 1) | ((upper & 3u) << 9);
      };
      const int r = ValidCells::row(y, z);
      valid.active_rows[std::size_t(r)] = row(active_words);
      valid.inside_rows[std::size_t(r)] = row(inside_words);
    }
  }
  valid.compute_cells();
}

}  // namespace levelset::surface_detail
