// best_fan_start: the fan apex of a contour polygon that maximises its smallest angle.
//
// Each fan triangle's smallest-angle cosine comes from its three squared side lengths (law of
// cosines), evaluated four triangles at a time in float. The triangles of the n fans of an
// n-gon are the triples {s, j, j + 1}; an "ear" {j - 1, j, j + 1} belongs to two fans, so
// there are n (n - 3) distinct ones (5-gon: 10 of the 15 fan slots). Which pairs form which
// triangle, and which triangles form which fan, depend on n only: compile-time tables replace
// the index arithmetic and its branches (the per-call loops were ~10 % of marching cubes on
// knot.off R = 512). Same values and the same choice as evaluating every fan slot.
#include <algorithm>
#include <array>
#include <bit>
#include <cstdint>

#include "surface/surface_common.hpp"

namespace levelset::surface_detail {

namespace {

constexpr int kMaxN = 12;
constexpr int kMaxPairs = kMaxN * (kMaxN - 1) / 2;  // 66
constexpr int kMaxTriangles = kMaxN * (kMaxN - 3);  // 108, distinct fan triangles
constexpr int kPadded = (kMaxTriangles + 3) / 4 * 4;

// The pair index of vertices i != j of an n-gon (pairs listed as (0,1), (0,2), ..., (1,2), ...).
constexpr int pair_index(int i, int j, int n) {
  if (i > j) std::swap(i, j);
  return i * n - i * (i + 1) / 2 + (j - i - 1);
}

struct FanTable {
  int pairs = 0, triangles = 0;
  std::array<std::array<std::uint8_t, 2>, kMaxPairs> pair_ends{};
  std::array<std::array<std::uint8_t, 3>, kMaxTriangles> sides{};  // pair indices of a triangle
  std::array<std::array<std::uint8_t, kMaxN - 2>, kMaxN> fan{};    // triangle indices of fan s
};

constexpr FanTable make_fan_table(int n) {
  FanTable t;
  for (int i = 0; i < n; ++i)
    for (int j = i + 1; j < n; ++j) t.pair_ends[std::size_t(t.pairs++)] = {std::uint8_t(i), std::uint8_t(j)};
  // Triangle {s, b, b + 1} is identified by its sorted triple; ears are met twice.
  std::array<std::array<int, 3>, kMaxTriangles> seen{};
  for (int s = 0; s < n; ++s)
    for (int i = 1; i <= n - 2; ++i) {
      const int b = (s + i) % n, c = (s + i + 1) % n;
      std::array<int, 3> key{s, b, c};
      std::sort(key.begin(), key.end());
      int found = -1;
      for (int k = 0; k < t.triangles; ++k)
        if (seen[std::size_t(k)] == key) found = k;
      if (found < 0) {
        found = t.triangles++;
        seen[std::size_t(found)] = key;
        t.sides[std::size_t(found)] = {std::uint8_t(pair_index(s, b, n)), std::uint8_t(pair_index(b, c, n)),
                                       std::uint8_t(pair_index(c, s, n))};
      }
      t.fan[std::size_t(s)][std::size_t(i - 1)] = std::uint8_t(found);
    }
  return t;
}

constexpr std::array<FanTable, kMaxN + 1> make_fan_tables() {
  std::array<FanTable, kMaxN + 1> all{};
  for (int n = 5; n <= kMaxN; ++n) all[std::size_t(n)] = make_fan_table(n);
  return all;
}

constexpr std::array<FanTable, kMaxN + 1> kFans = make_fan_tables();
static_assert(kFans[5].triangles == 10 && kFans[6].triangles == 18 && kFans[kMaxN].triangles == kMaxTriangles);

// Smallest-angle cosines of count triangles (squared sides a, b, c; padded to 4): 1 where
// degenerate.
void smallest_angle_cosines(const float* sa, const float* sb, const float* sc, int count, float* cosine) {
#if defined(__SSE2__)
  const __m128 zero = _mm_setzero_ps(), half = _mm_set1_ps(0.5f), one = _mm_set1_ps(1.0f);
  for (int k = 0; k < count; k += 4) {
    const __m128 a = _mm_load_ps(sa + k), b = _mm_load_ps(sb + k), c = _mm_load_ps(sc + k);
    const __m128 lo = _mm_min_ps(_mm_min_ps(a, b), c), hi = _mm_max_ps(_mm_max_ps(a, b), c);
    const __m128 mid = _mm_max_ps(_mm_min_ps(a, b), _mm_min_ps(_mm_max_ps(a, b), c));
    const __m128 prod = _mm_mul_ps(hi, mid);
    const __m128 q = _mm_div_ps(_mm_mul_ps(_mm_sub_ps(_mm_add_ps(hi, mid), lo), half), _mm_sqrt_ps(prod));
    const __m128 ok = _mm_and_ps(_mm_cmpgt_ps(lo, zero), _mm_cmpgt_ps(prod, zero));
    _mm_store_ps(cosine + k, _mm_or_ps(_mm_and_ps(ok, q), _mm_andnot_ps(ok, one)));
  }
#else
  for (int k = 0; k < count; ++k) cosine[k] = float(max_cos_from_squares(sa[k], sb[k], sc[k]));
#endif
}

// The apex for an N-gon: fixed trip counts (unrolled, no loop exits to mispredict) and a
// branch-free choice. Smallest-angle cosines lie in [0.5, 1] (a triangle's smallest angle is
// at most 60 degrees), so their bits order like the floats; the apex index in the low bits
// makes the first apex win ties.
template <int N>
int best_fan_start_n(const Vec3d* p) {
  constexpr const FanTable& t = kFans[N];
  constexpr int kPairs = N * (N - 1) / 2, kTriangles = N * (N - 3), kCount = (kTriangles + 3) / 4 * 4;
  float d2[kPairs];
  for (int k = 0; k < kPairs; ++k) {
    const Vec3d e = p[t.pair_ends[std::size_t(k)][1]] - p[t.pair_ends[std::size_t(k)][0]];
    d2[k] = float(dot(e, e));
  }
  alignas(16) float sa[kCount], sb[kCount], sc[kCount], cosine[kCount];
  for (int k = 0; k < kTriangles; ++k) {
    const auto& s = t.sides[std::size_t(k)];
    sa[k] = d2[s[0]], sb[k] = d2[s[1]], sc[k] = d2[s[2]];
  }
  for (int k = kTriangles; k < kCount; ++k) sa[k] = sb[k] = sc[k] = 1.0f;
  smallest_angle_cosines(sa, sb, sc, kCount, cosine);
  std::uint64_t best = ~std::uint64_t{0};
  for (int s = 0; s < N; ++s) {
    float worst = cosine[t.fan[std::size_t(s)][0]];
    for (int i = 1; i < N - 2; ++i) worst = std::max(worst, cosine[t.fan[std::size_t(s)][std::size_t(i)]]);
    best = std::min(best, std::uint64_t(std::bit_cast<std::uint32_t>(worst)) << 8 | std::uint64_t(s));
  }
  return int(best & 0xffu);
}

}  // namespace

int best_fan_start(const Vec3d* p, int n) {
  switch (n) {
    case 4: return split_02(p) ? 0 : 1;
    case 5: return best_fan_start_n<5>(p);
    case 6: return best_fan_start_n<6>(p);
    case 7: return best_fan_start_n<7>(p);
    case 8: return best_fan_start_n<8>(p);
    case 9: return best_fan_start_n<9>(p);
    case 10: return best_fan_start_n<10>(p);
    case 11: return best_fan_start_n<11>(p);
    case 12: return best_fan_start_n<12>(p);
    default: return 0;
  }
}

}  // namespace levelset::surface_detail
