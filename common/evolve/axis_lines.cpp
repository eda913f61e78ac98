#include "evolve/axis_lines.hpp"

#include <algorithm>
#include <bit>

#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__)
#include <immintrin.h>
#define LEVELSET_ROW_PACK_AVX2 1
#endif

namespace levelset::evolve::detail {

namespace {

constexpr int kLen = AxisLines::kLen;
constexpr std::uint32_t kAll = (1u << kLen) - 1;
constexpr std::uint32_t kOwn = ((1u << kBrickDim) - 1) << (-kLo);  // the brick's samples

// Bits [lo, hi] (none when hi < lo).
constexpr std::uint32_t bit_range(int lo, int hi) {
  return hi < lo ? 0u : ((hi >= 31 ? ~0u : (2u << hi) - 1u) & ~((1u << lo) - 1u));
}

// Fills the samples `fill` of a gap (in v, sample g at v[g * vstep]) from the polynomial through its last active sample `last`
// and up to two more behind it, away from the gap (dir = +1: the gap lies above `last`):
// through (0, p1), (-1, p2), (-2, p3) evaluated t = |g - last| steps into the gap; linear
// through two samples, constant through one. Without branches on the sample count.
void fill_from(float* v, std::ptrdiff_t vstep, const float* src, std::ptrdiff_t stride, std::uint32_t active,
               int last, int dir, std::uint32_t fill) {
  auto on = [&](int q) { return q >= 0 && q < kLen && ((active >> q) & 1u); };
  auto at = [&](int q) { return double(src[q * stride]); };
  const int run = on(last - dir) ? (on(last - 2 * dir) ? 3 : 2) : 1;
  const double p1 = at(last), p2 = run >= 2 ? at(last - dir) : p1, p3 = run >= 3 ? at(last - 2 * dir) : p2;
  const double a = run >= 3 ? 1.5 * p1 - 2.0 * p2 + 0.5 * p3 : run == 2 ? p1 - p2 : 0.0;
  const double b = run >= 3 ? p1 - 2.0 * p2 + p3 : 0.0;
  for (; fill; fill &= fill - 1) {
    const int g = std::countr_zero(fill);
    const double t = double((g - last) * dir);
    v[g * vstep] = float(p1 + t * a + 0.5 * t * t * b);
  }
}

// Fills the `need`ed inactive samples of one line (`active` bit k: sample k is in the band):
// each from the nearer side of its gap (the left on a tie), when that side's last active
// sample is at most `reach` away; samples of a gap with no active side stay as they are.
// The active samples are read from the tile (src, with its stride along the line), not from
// the line just copied from it: a load right after a wide vector store of the copy would wait
// for store forwarding.
void extrapolate_line(float* v, std::ptrdiff_t vstep, const float* src, std::ptrdiff_t stride, std::uint32_t active,
                      std::uint32_t need, int reach) {
  while (need) {
    const int g0 = std::countr_zero(need);
    // The gap [k, e) around g0.
    const std::uint32_t below = active & ((1u << g0) - 1), above = active & ~((1u << g0) - 1);
    const int k = below ? 32 - std::countl_zero(below) : 0, e = above ? std::countr_zero(above) : kLen;
    const bool left = k > 0, right = e < kLen;
    // Samples g with dl = g - k + 1 <= dr = e - g take the left side (all of them without a
    // right side), each side within `reach`.
    const int split = right ? (e + k - 1) / 2 : e - 1;
    if (left) fill_from(v, vstep, src, stride, active, k - 1, 1, need & bit_range(k, std::min(split, k + reach - 1)));
    if (right)
      fill_from(v, vstep, src, stride, active, e, -1, need & bit_range(std::max(left ? split + 1 : k, e - reach), e - 1));
    need &= ~bit_range(k, e - 1);
  }
}

// The inactive samples an upwind stencil of half-width `reach` around an active brick sample
// reads.
std::uint32_t needed_samples(std::uint32_t active, int reach) {
  const std::uint32_t centres = active & kOwn;
  std::uint32_t spread = centres;
  for (int r = 1; r <= reach; ++r) spread |= (centres << r) | (centres >> r);
  return spread & ~active & kAll;
}

// Extrapolates the samples a line needs (v: its first sample in AxisLines, vstep apart; src:
// the tile's, stride apart), which already holds the tile's copy.
void extrapolate_needed(float* v, std::ptrdiff_t vstep, const float* src, std::ptrdiff_t stride, std::uint32_t active,
                        int reach) {
  if (active == kAll) return;
  const std::uint32_t need = needed_samples(active, reach);
  if (need) extrapolate_line(v, vstep, src, stride, active, need, reach);
}

// Transposes the brick's 8 columns of kLen tile rows: bit k of out[i] is bit i - kLo of
// row_at(k). Eight columns at a time in the bytes of two words (k < 8 and k >= 8).
template <class Rows>
std::array<std::uint32_t, kBrickDim> brick_columns(Rows row_at) {
  std::uint64_t lo = 0, hi = 0;
  for (int k = 0; k < kLen; ++k) {
    // Byte i of t holds the row's brick bits; keep bit i in byte i, then move it to bit 0.
    const std::uint64_t t = std::uint64_t((row_at(k) >> -kLo) & 0xffu) * 0x0101010101010101ull;
    const std::uint64_t v = (((t & 0x8040201008040201ull) + 0x7f7f7f7f7f7f7f7full) & 0x8080808080808080ull) >> 7;
    if (k < 8)
      lo |= v << k;
    else
      hi |= v << (k - 8);
  }
  std::array<std::uint32_t, kBrickDim> out;
  for (int i = 0; i < kBrickDim; ++i)
    out[std::size_t(i)] = std::uint32_t((lo >> (8 * i)) & 0xffu) | std::uint32_t((hi >> (8 * i)) & 0xffu) << 8;
  return out;
}


// N floats, inline (std::copy_n of a few floats became a call to memmove).
template <int N>
void copy_run(const float* from, float* to) {
  for (int i = 0; i < N; ++i) to[i] = from[i];
}

// The first of brick row (y, z)'s samples along axis a at offset -kStencilReach from its
// centres: sample j of the row's centre x is first[j * AxisLines::step(a) + x].
const float* row_samples(const AxisLines& lines, int a, int y, int z) {
  return a == 0   ? lines.at(0, 0, y, z, -kLo - kStencilReach)
         : a == 1 ? lines.at(1, 0, y, z, y - kLo - kStencilReach)
                  : lines.at(2, 0, y, z, z - kLo - kStencilReach);
}

// The brick's rows that hold an active voxel, in ascending local index: the row's mask (bit
// x) and its y and z.
struct ActiveRows {
  int count = 0;
  std::array<std::uint8_t, kBrickDim * kBrickDim> mask, y, z;
};

ActiveRows active_rows(const BrickMask& active) {
  ActiveRows rows;
  for (int z = 0; z < kBrickDim; ++z)
    for (int y = 0; y < kBrickDim; ++y)
      if (const unsigned m = unsigned(active.words[std::size_t(z)] >> (8 * y)) & 0xffu; m != 0) {
        rows.mask[std::size_t(rows.count)] = std::uint8_t(m);
        rows.y[std::size_t(rows.count)] = std::uint8_t(y);
        rows.z[std::size_t(rows.count++)] = std::uint8_t(z);
      }
  return rows;
}

// gather_centre_samples, one sample at a time.
int gather_rows_portable(const AxisLines& lines, const ActiveRows& rows, int a, CentreSamples& s) {
  int k = 0;
  for (int r = 0; r < rows.count; ++r) {
    const unsigned m = rows.mask[std::size_t(r)];
    const float* first = row_samples(lines, a, rows.y[std::size_t(r)], rows.z[std::size_t(r)]);
    for (int j = 0; j < CentreSamples::kCount; ++j) {
      const float* run = first + j * AxisLines::step(a);
      float* out = s.at[std::size_t(j)].data() + k;
      int t = 0;
      for (int x = 0; x < kBrickDim; ++x) {  // branch-free packing
        out[t] = run[x];
        t += int((m >> x) & 1u);
      }
    }
    k += std::popcount(m);
  }
  return k;
}

#ifdef LEVELSET_ROW_PACK_AVX2
// kPack[m]: the positions of m's set bits, ascending, then zeros (a permutation that packs a
// row's active lanes to its front).
struct PackTable {
  alignas(32) std::int32_t lanes[256][kBrickDim];
};
constexpr PackTable make_pack_table() {
  PackTable t{};
  for (unsigned m = 0; m < 256; ++m) {
    int n = 0;
    for (int x = 0; x < kBrickDim; ++x)
      if ((m >> x) & 1u) t.lanes[m][n++] = x;
  }
  return t;
}
constexpr PackTable kPack = make_pack_table();

// gather_rows_portable with one load, lane permutation and store per run.
__attribute__((target("avx2"))) int gather_rows_avx2(const AxisLines& lines, const ActiveRows& rows, int a,
                                                     CentreSamples& s) {
  int k = 0;
  for (int r = 0; r < rows.count; ++r) {
    const unsigned m = rows.mask[std::size_t(r)];
    const float* first = row_samples(lines, a, rows.y[std::size_t(r)], rows.z[std::size_t(r)]);
    const __m256i perm = _mm256_load_si256(reinterpret_cast<const __m256i*>(kPack.lanes[m]));
    for (int j = 0; j < CentreSamples::kCount; ++j)
      _mm256_storeu_ps(s.at[std::size_t(j)].data() + k,
                       _mm256_permutevar8x32_ps(_mm256_loadu_ps(first + j * AxisLines::step(a)), perm));
    k += std::popcount(m);
  }
  return k;
}
#endif

// gather_centre_samples over the brick's active rows.
int gather_rows(const AxisLines& lines, const ActiveRows& rows, int a, CentreSamples& s, bool allow_vector) {
#ifdef LEVELSET_ROW_PACK_AVX2
  static const bool avx2 = __builtin_cpu_supports("avx2");
  if (avx2 && allow_vector) return gather_rows_avx2(lines, rows, a, s);
#else
  (void)allow_vector;
#endif
  return gather_rows_portable(lines, rows, a, s);
}

}  // namespace

void fill_axis_lines(const float* tile, const std::uint32_t* rows, int reach, AxisLines& lines) {
  auto row = [&](int ty, int tz) { return rows[std::size_t(ty + kDim * tz)]; };  // tile-index rows
  for (int j = 0; j < kBrickDim; ++j) {
    const int tj = j - kLo;
    // Active bits along y of the lines (x, z) = (i, j), and along z of the lines (x, y) = (i, j).
    const std::array<std::uint32_t, kBrickDim> ys = brick_columns([&](int k) { return row(k, tj); });
    const std::array<std::uint32_t, kBrickDim> zs = brick_columns([&](int k) { return row(tj, k); });
    // The y lines of the plane z = j and the z lines of the plane y = j: runs of 8 along x.
    for (int p = 0; p < kLen; ++p) {
      copy_run<kBrickDim>(tile + tile_index(0, p + kLo, j), lines.at(1, 0, 0, j, p));
      copy_run<kBrickDim>(tile + tile_index(0, j, p + kLo), lines.at(2, 0, j, 0, p));
    }
    for (int i = 0; i < kBrickDim; ++i) {
      // x lines: (y, z) = (i, j): one row.
      if (const std::uint32_t act = row(i - kLo, tj); act & kOwn) {
        const float* src = tile + tile_index(kLo, i, j);
        copy_run<kLen>(src, lines.at(0, 0, i, j, 0));
        extrapolate_needed(lines.at(0, 0, i, j, 0), 1, src, 1, act, reach);
      }
      if (const std::uint32_t ay = ys[std::size_t(i)]; ay & kOwn)
        extrapolate_needed(lines.at(1, i, 0, j, 0), kBrickDim, tile + tile_index(i, kLo, j), kDim, ay, reach);
      if (const std::uint32_t az = zs[std::size_t(i)]; az & kOwn)
        extrapolate_needed(lines.at(2, i, j, 0, 0), kBrickDim, tile + tile_index(i, j, kLo), kDim * kDim, az, reach);
    }
  }
}

int gather_centre_samples(const AxisLines& lines, const BrickMask& active, int a, CentreSamples& s, bool allow_vector) {
  return gather_rows(lines, active_rows(active), a, s, allow_vector);
}

void upwind_sides(const AxisLines& lines, const BrickMask& active, Scheme scheme, const SidesWanted& want,
                  UpwindSides& sides) {
  const ActiveRows rows = active_rows(active);
  for (int a = 0; a < 3; ++a) {
    const bool minus = want.minus[std::size_t(a)], plus = want.plus[std::size_t(a)];
    if (!minus && !plus) continue;
    const int k = gather_rows(lines, rows, a, sides.samples, true);
    one_sided_batch(sides.samples, k, scheme, minus ? sides.minus[std::size_t(a)].data() : nullptr,
                    plus ? sides.plus[std::size_t(a)].data() : nullptr);
  }
}

}  // namespace levelset::evolve::detail
