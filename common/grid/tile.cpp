#include "grid/tile.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cstring>

#if defined(__x86_64__)
#include <immintrin.h>
#endif
#include <string>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "core/error.hpp"
#include "core/huge_pages.hpp"

namespace levelset {

namespace {

// kActiveBefore[m], nibble x: the number of set bits of the byte m below bit x.
constexpr std::array<std::uint32_t, 256> make_active_before() {
  std::array<std::uint32_t, 256> t{};
  for (std::uint32_t m = 0; m < 256; ++m) {
    std::uint32_t acc = 0, packed = 0;
    for (int x = 0; x < 8; ++x) {
      packed |= acc << (4 * x);
      acc += (m >> x) & 1u;
    }
    t[m] = packed;
  }
  return t;
}
constexpr std::array<std::uint32_t, 256> kActiveBefore = make_active_before();

}  // namespace

namespace {

// Per slot of the 3x3x3 neighbourhood, the ways to reach it by one face link from a slot one
// step nearer the centre (axis by axis, as the search below tries them), slots in the order
// faces, edges, corners (each resolved after the ones it is reached from).
struct SlotPaths {
  std::uint8_t slot = 0, count = 0;
  std::array<std::uint8_t, 3> from{}, face{};
};

constexpr std::array<SlotPaths, 26> make_slot_paths() {
  std::array<SlotPaths, 26> out{};
  int at = 0;
  for (int axes = 1; axes <= 3; ++axes)
    for (int k = 0; k < 27; ++k) {
      const Coord d = Neighborhood::offset(k);
      if ((d.x != 0) + (d.y != 0) + (d.z != 0) != axes) continue;
      SlotPaths p;
      p.slot = std::uint8_t(k);
      for (int a = 0; a < 3; ++a) {
        if (d[a] == 0) continue;
        Coord nearer = d;
        nearer[a] = 0;
        p.from[p.count] = std::uint8_t(Neighborhood::slot(nearer.x, nearer.y, nearer.z));
        p.face[p.count] = std::uint8_t(2 * a + (d[a] > 0 ? 1 : 0));
        ++p.count;
      }
      out[std::size_t(at++)] = p;
    }
  return out;
}

constexpr std::array<SlotPaths, 26> kSlotPaths = make_slot_paths();

}  // namespace

Neighborhood brick_neighborhood(const NarrowBand& band, std::uint32_t brick) {
  Neighborhood n;
  n.fill(kNoBrick);
  n[Neighborhood::slot(0, 0, 0)] = brick;
  // Faces, then edges, then corners: each one face link from a resolved brick one step nearer;
  // a hash lookup only when every such path is unallocated (the brick may still exist).
  for (const SlotPaths& p : kSlotPaths) {
    std::uint32_t found = kNoBrick;
    bool path = false;
    for (int i = 0; i < p.count && found == kNoBrick; ++i) {
      const std::uint32_t from = n[p.from[std::size_t(i)]];
      if (from == kNoBrick) continue;
      path = true;
      found = band.neighbor(from, Face(p.face[std::size_t(i)]));
    }
    if (!path) found = band.find_brick(band.bricks()[brick].coord + Neighborhood::offset(p.slot));
    n[p.slot] = found;
  }
  return n;
}

Neighborhood brick_star(const NarrowBand& band, std::uint32_t brick) {
  Neighborhood n;
  n.fill(kNoBrick);
  n[Neighborhood::slot(0, 0, 0)] = brick;
  for (int f = 0; f < 6; ++f) {
    Coord d{0, 0, 0};
    d[f >> 1] = (f & 1) ? 1 : -1;
    n[std::size_t(Neighborhood::slot(d.x, d.y, d.z))] = band.neighbor(brick, Face(f));
  }
  return n;
}

namespace {

// One brick's 512 values from its packed active values and its active and inside words:
// inactive voxels +-bg by their stored sign.
void decode_words_portable(const float* v, const std::uint64_t* active, const std::uint64_t* inside, float bg,
                           float* out) {
  const float sign_value[2] = {bg, -bg};  // by inside bit
  // A z-slice (64 voxels, one word of each mask) at a time: the signs branch-free, then the
  // active values a row (8 voxels, one byte) at a time, a full row in one copy.
  for (int w = 0; w < 8; ++w) {
    float* o = out + 64 * w;
    if (inside[w] == 0 || inside[w] == ~std::uint64_t{0}) std::fill_n(o, 64, sign_value[inside[w] & 1]);
    else
      for (int i = 0; i < 64; ++i) o[i] = sign_value[(inside[w] >> i) & 1];
    for (int r = 0; r < 8; ++r) {
      const std::uint32_t row = std::uint32_t(active[w] >> (8 * r)) & 0xffu;
      if (row == 0xffu) {
        std::memcpy(o + 8 * r, v, 8 * sizeof(float));
        v += 8;
        continue;
      }
      for (std::uint32_t m = row; m != 0; m &= m - 1) o[8 * r + std::countr_zero(m)] = *v++;
    }
  }
}

#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__)
#define LEVELSET_DECODE_AVX512 1
// The same, 16 voxels per instruction: the sign blend, then an expanding load puts the next
// popcount(mask) packed values into the active lanes (masked-off lanes read no memory).
__attribute__((target("avx512f"))) void decode_words_avx512(const float* v, const std::uint64_t* active,
                                                             const std::uint64_t* inside, float bg, float* out) {
  const __m512 plus = _mm512_set1_ps(bg), minus = _mm512_set1_ps(-bg);
  for (int w = 0; w < 8; ++w)
    for (int q = 0; q < 4; ++q) {
      const __mmask16 act = __mmask16(active[w] >> (16 * q)), in = __mmask16(inside[w] >> (16 * q));
      const __m512 signs = _mm512_mask_blend_ps(in, plus, minus);
      _mm512_storeu_ps(out + 64 * w + 16 * q, _mm512_mask_expandloadu_ps(signs, act, v));
      v += std::popcount(unsigned(act));
    }
}
#endif

}  // namespace

void decode_brick_portable(const NarrowBand& band, std::uint32_t brick, std::span<float, kBrickVoxels> out) {
  const Brick& br = band.bricks()[brick];
  std::uint64_t inside[8];
  for (int w = 0; w < 8; ++w) inside[w] = band.stored_inside_word(br, w);
  decode_words_portable(band.values().data() + br.value_offset, br.active.words.data(), inside, band.background(),
                        out.data());
}

void decode_brick(const NarrowBand& band, std::uint32_t brick, std::span<float, kBrickVoxels> out) {
  const Brick& br = band.bricks()[brick];
  std::uint64_t inside[8];
  for (int w = 0; w < 8; ++w) inside[w] = band.stored_inside_word(br, w);
  const float* v = band.values().data() + br.value_offset;
#if defined(LEVELSET_DECODE_AVX512)
  static const bool avx512 = __builtin_cpu_supports("avx512f");
  if (avx512) {
    decode_words_avx512(v, br.active.words.data(), inside, band.background(), out.data());
    return;
  }
#endif
  decode_words_portable(v, br.active.words.data(), inside, band.background(), out.data());
}

void gather_tile(const NarrowBand& band, std::uint32_t brick, int halo, std::span<float> out) {
  gather_tile(band, brick, halo, out, {});
}

void gather_tile(const NarrowBand& band, std::uint32_t brick, int halo, std::span<float> out,
                 std::span<std::uint32_t> active_rows) {
  if (halo < 0 || halo > kBrickDim)
    throw Error(ErrorCode::InvalidArgument, "gather_tile", "halo must be in [0, 8]");
  gather_box(band, brick, -halo, kBrickDim + halo, out, active_rows);
}

void gather_box(const NarrowBand& band, std::uint32_t brick, int lo, int hi, std::span<float> out,
                std::span<std::uint32_t> active_rows) {
  gather_box(band, brick_neighborhood(band, brick), lo, hi, out, active_rows);
}

namespace {

// Copies `width` (<= 8) floats: a fixed-size copy per width, a few moves each (a loop of
// runtime length became vector code with overlap checks and a scalar tail: the halos' rows of
// 3 cost more than the brick's rows of 8).
template <int N>
inline void copy_floats(const float* src, float* dst) {
  std::array<float, N> row;
  std::memcpy(row.data(), src, sizeof row);
  std::memcpy(dst, row.data(), sizeof row);
}
inline void copy_row(const float* src, float* dst, int width) {
  switch (width) {
    case 8: return copy_floats<8>(src, dst);
    case 7: return copy_floats<7>(src, dst);
    case 6: return copy_floats<6>(src, dst);
    case 5: return copy_floats<5>(src, dst);
    case 4: return copy_floats<4>(src, dst);
    case 3: return copy_floats<3>(src, dst);
    case 2: return copy_floats<2>(src, dst);
    case 1: return copy_floats<1>(src, dst);
    default: return;
  }
}

// Sign of the unallocated neighbour d of around's brick (one sign for the whole brick: band
// invariant), by the band's x-row rule at the neighbour's local voxel nlo; when the next brick
// along +x is a neighbour here, that rule reads its first column, without the search.
bool unallocated_inside(const NarrowBand& band, const Neighborhood& around, const Coord& d, const int nlo[3]) {
  const std::uint32_t next = d.x < 1 ? around[std::size_t(Neighborhood::slot(d.x + 1, d.y, d.z))] : kNoBrick;
  if (next != kNoBrick) return band.voxel_inside(next, local_index(0, nlo[1], nlo[2]));
  const Coord self = band.bricks()[around[std::size_t(Neighborhood::slot(0, 0, 0))]].coord;
  const Coord voxel = brick_origin(self + d) + Coord{nlo[0], nlo[1], nlo[2]};
  // With the -x neighbour known, no search (the search was ~4 % of marching cubes).
  const std::uint32_t lower = d.x > -1 ? around[std::size_t(Neighborhood::slot(d.x - 1, d.y, d.z))] : kNoBrick;
  if (lower != kNoBrick) return band.is_inside_unallocated_next_to(lower, voxel);
  return band.is_inside_unallocated(voxel);
}

// Local range [nlo, nhi) per axis of neighbour d that falls into the box [lo, hi)^3; false
// when it is empty.
bool neighbor_range(const Coord& d, int lo, int hi, int nlo[3], int nhi[3]) {
  bool empty = false;
  for (int a = 0; a < 3; ++a) {
    nlo[a] = d[a] < 0 ? kBrickDim + lo : 0;
    nhi[a] = d[a] > 0 ? hi - kBrickDim : kBrickDim;
    empty |= nlo[a] >= nhi[a];
  }
  return !empty;
}

// The box of gather_box, its unallocated neighbours filled here; fill_row(nb, brick, z, y, x0,
// x1, width, dst) writes local x in [x0, x1) (width = x1 - x0) of row (y, z) of allocated
// neighbour nb to dst[x].
template <typename FillRow>
void gather_box_rows(const NarrowBand& band, const Neighborhood& around, int lo, int hi, std::span<float> out,
                     std::span<std::uint32_t> active_rows, GatherRegion region, NeighborSigns* signs,
                     FillRow&& fill_row) {
  if (lo < -kBrickDim || lo > 0 || hi < kBrickDim || hi > 2 * kBrickDim)
    throw Error(ErrorCode::InvalidArgument, "gather_box", "need -8 <= lo <= 0 and 8 <= hi <= 16");
  const std::size_t dim = std::size_t(hi - lo);
  if (out.size() != dim * dim * dim)
    throw Error(ErrorCode::InvalidArgument, "gather_box", "output size must be (hi - lo)^3");
  const bool rows = !active_rows.empty();
  if (rows && active_rows.size() != dim * dim)
    throw Error(ErrorCode::InvalidArgument, "gather_box", "active_rows size must be (hi - lo)^2");
  if (rows) std::fill(active_rows.begin(), active_rows.end(), 0u);
  const float bg = band.background();
  // Box index of local voxel (x, y, z).
  auto index = [&](int x, int y, int z) {
    return std::size_t(x - lo) + dim * (std::size_t(y - lo) + dim * std::size_t(z - lo));
  };
  for (int dz = -1; dz <= 1; ++dz) {
    for (int dy = -1; dy <= 1; ++dy) {
      for (int dx = -1; dx <= 1; ++dx) {
        const Coord d{dx, dy, dz};
        if (region == GatherRegion::Star && (dx != 0) + (dy != 0) + (dz != 0) > 1) continue;
        int nlo[3], nhi[3];
        if (!neighbor_range(d, lo, hi, nlo, nhi)) continue;
        const std::uint32_t nb = around[std::size_t(Neighborhood::slot(dx, dy, dz))];
        const int width = nhi[0] - nlo[0];
        if (nb == kNoBrick) {
          // Unallocated: one sign for the whole brick (band invariant), by the band's x-row
          // rule; when the next brick along +x is a neighbour here, that rule reads its first
          // column, without the search.
          const std::uint32_t bit = 1u << Neighborhood::slot(dx, dy, dz);
          bool inside;
          if (signs && (signs->known & bit)) {
            inside = (signs->inside & bit) != 0;
          } else {
            inside = unallocated_inside(band, around, d, nlo);
            if (signs) {
              signs->known |= bit;
              if (inside) signs->inside |= bit;
            }
          }
          const float v = inside ? -bg : bg;
          for (int z = nlo[2]; z < nhi[2]; ++z)
            for (int y = nlo[1]; y < nhi[1]; ++y)
              std::fill_n(&out[index(nlo[0] + dx * kBrickDim, y + dy * kBrickDim, z + dz * kBrickDim)], width, v);
          continue;
        }
        const Brick& br = band.bricks()[nb];
        const std::uint32_t xmask = ((1u << nhi[0]) - 1u) & ~((1u << nlo[0]) - 1u);
        const int shift = nlo[0] + dx * kBrickDim - lo;  // box bit of local x = nlo[0]
        for (int z = nlo[2]; z < nhi[2]; ++z) {
          const std::uint64_t act_word = br.active.words[std::size_t(z)];
          for (int y = nlo[1]; y < nhi[1]; ++y) {
            const std::size_t row = index(lo, y + dy * kBrickDim, z + dz * kBrickDim);
            // Box index of local x: row + (x + dx * kBrickDim - lo), the last term >= 0. Alone,
            // dx * kBrickDim - lo is negative for dx = -1, so no pointer is formed from it
            // (UBSan: pointer overflow); the unsigned sum wraps back exactly.
            const std::size_t base = row - std::size_t(lo - dx * kBrickDim);
            fill_row(nb, br, z, y, nlo[0], nhi[0], width, out.data() + base);
            if (rows) {
              const std::uint32_t act = std::uint32_t(act_word >> (8 * y)) & 0xffu;
              active_rows[std::size_t(y + dy * kBrickDim - lo) + dim * std::size_t(z + dz * kBrickDim - lo)] |=
                  ((act & xmask) >> nlo[0]) << shift;
            }
          }
        }
      }
    }
  }
}

}  // namespace

void gather_box(const NarrowBand& band, const Neighborhood& around, int lo, int hi, std::span<float> out,
                std::span<std::uint32_t> active_rows) {
  const float bg = band.background();
  const float sign_value[2] = {bg, -bg};  // by inside bit
  const float* all_values = band.values().data();
  // A row of a brick is one byte of its masks, and its active values are contiguous in the
  // packed storage.
  gather_box_rows(band, around, lo, hi, out, active_rows, GatherRegion::Box, nullptr,
                  [&](std::uint32_t, const Brick& br, int z, int y, int x0, int x1, int width, float* dst) {
    const std::uint64_t act_word = br.active.words[std::size_t(z)];
    const int bit0 = 8 * y;
    const std::uint32_t act = std::uint32_t(act_word >> bit0) & 0xffu;
    const std::uint32_t xmask = ((1u << x1) - 1u) & ~((1u << x0) - 1u);
    const float* row_values = all_values + br.value_offset + br.rank_base(z) +
                              std::popcount(act_word & ((std::uint64_t{1} << bit0) - 1));
    const std::uint32_t before = kActiveBefore[act];
    if ((act & xmask) == xmask) {
      // Every voxel of the range active (most rows of a wide band): one contiguous copy.
      copy_row(row_values + ((before >> (4 * x0)) & 15u), dst + x0, width);
      return;
    }
    // Otherwise branch-free per voxel: the value's address is selected, not branched on (the
    // active pattern of a partial row is unpredictable).
    const std::uint32_t ins = std::uint32_t(band.stored_inside_word(br, z) >> bit0) & 0xffu;
    for (int x = x0; x < x1; ++x) {
      const float* src = ((act >> x) & 1u) ? row_values + ((before >> (4 * x)) & 15u) : &sign_value[(ins >> x) & 1u];
      dst[x] = *src;
    }
  });
}

NeighborSigns resolve_neighbor_signs(const NarrowBand& band, const Neighborhood& around, int lo, int hi) {
  NeighborSigns signs;
  for (int k = 0; k < 27; ++k) {
    const Coord d = Neighborhood::offset(k);
    int nlo[3], nhi[3];
    if (around[std::size_t(k)] != kNoBrick || !neighbor_range(d, lo, hi, nlo, nhi)) continue;
    signs.known |= 1u << k;
    if (unallocated_inside(band, around, d, nlo)) signs.inside |= 1u << k;
  }
  return signs;
}

DecodedBricks decode_bricks(const NarrowBand& band) {
  DecodedBricks out;
  // Not value-initialised: every entry is written below, in parallel; the pages (huge ones
  // where the buffer is large) are faulted in first by one call, not by a trap per page.
  resize_with_huge_pages(out.data, band.brick_count() * std::size_t(kBrickVoxels));
  tbb::parallel_for(tbb::blocked_range<std::uint32_t>(0, std::uint32_t(band.brick_count()), 64),
                    [&](const tbb::blocked_range<std::uint32_t>& r) {
                      for (std::uint32_t b = r.begin(); b != r.end(); ++b)
                        decode_brick(band, b,
                                     std::span<float, kBrickVoxels>(out.data.data() + std::size_t(b) * kBrickVoxels,
                                                                    kBrickVoxels));
                    });
  return out;
}

void gather_box(const NarrowBand& band, std::span<const float> decoded, const Neighborhood& around, int lo, int hi,
                std::span<float> out, std::span<std::uint32_t> active_rows, GatherRegion region, NeighborSigns* signs) {
  if (decoded.size() != band.brick_count() * std::size_t(kBrickVoxels))
    throw Error(ErrorCode::InvalidArgument, "gather_box", "decoded bricks do not match the band");
  gather_box_rows(band, around, lo, hi, out, active_rows, region, signs,
                  [&](std::uint32_t nb, const Brick&, int z, int y, int x0, int, int width, float* dst) {
    copy_row(decoded.data() + std::size_t(nb) * kBrickVoxels + std::size_t(local_index(x0, y, z)), dst + x0, width);
  });
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
