#include "distance/eikonal_sweep.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "distance/eikonal_rounds.hpp"
#include "distance/eikonal_update.hpp"
#include "distance/redistance_tile.hpp"

namespace levelset::detail {

namespace {

// The mask permuted so that visiting its bits in increasing order visits the voxels of the
// original in the lexicographic order with the axes in `flip` (bit a) reversed.
inline std::uint64_t reverse_bits_in_bytes(std::uint64_t v) {
  v = ((v >> 1) & 0x5555555555555555ull) | ((v & 0x5555555555555555ull) << 1);
  v = ((v >> 2) & 0x3333333333333333ull) | ((v & 0x3333333333333333ull) << 2);
  return ((v >> 4) & 0x0f0f0f0f0f0f0f0full) | ((v & 0x0f0f0f0f0f0f0f0full) << 4);
}
BrickMask permute(const BrickMask& m, int flip) {
  BrickMask r;
  for (int w = 0; w < 8; ++w) {
    std::uint64_t v = m.words[(flip & 4) ? 7 - w : w];
    if (flip & 2) v = __builtin_bswap64(v);
    if (flip & 1) v = reverse_bits_in_bytes(v);
    r.words[w] = v;
  }
  return r;
}
constexpr int flip_xor(int flip) { return ((flip & 1) ? 7 : 0) | ((flip & 2) ? 56 : 0) | ((flip & 4) ? 448 : 0); }
// The 8 orderings, opposite directions in succession.
constexpr int kOrderings[8] = {0, 7, 1, 6, 2, 5, 3, 4};

// Copies the brick's distances and `Halo` layers of each face neighbour into a tile;
// missing neighbours leave +inf. Signed: inside voxels negative (second-order stencils
// need the sign to reach across the zero level).
template <int Halo, bool Signed>
void load_tile(const RedistanceDomain& w, std::uint32_t b, float* tile) {
  using G = TileGeom<Halo>;
  std::fill(tile, tile + G::kVoxels, kInf);
  auto put = [&](std::uint32_t src, int n, int t) {
    const float v = w.values(src)[n];
    tile[t] = Signed && w.inside[src].test(n) ? -v : v;
  };
  for (int n = 0; n < kBrickVoxels; ++n) put(b, n, kTileGeom<Halo>.tile_of[n]);
  for_each_halo_voxel<Halo>(w.nbr[b], put);
}

// Voxel-level work lists: a sweep evaluates only voxels whose stencil saw a change since
// their last evaluation, which gives the same values as evaluating all of them (the update
// is a function of the stencil) and makes the confirming sweep of a converged brick free.
// Within one z-slice word: the voxels within `Reach` along x or y of slice position i.
template <int Reach>
struct SliceReach {
  std::array<std::uint64_t, 64> mask{};
  constexpr SliceReach() {
    for (int i = 0; i < 64; ++i) {
      const int x = i & 7, y = i >> 3;
      for (int r = 1; r <= Reach; ++r) {
        if (x - r >= 0) mask[i] |= std::uint64_t{1} << (i - r);
        if (x + r < 8) mask[i] |= std::uint64_t{1} << (i + r);
        if (y - r >= 0) mask[i] |= std::uint64_t{1} << (i - 8 * r);
        if (y + r < 8) mask[i] |= std::uint64_t{1} << (i + 8 * r);
      }
    }
  }
};
template <int Reach>
inline constexpr SliceReach<Reach> kSliceReach{};

// Marks the voxels whose stencil contains voxel n (those in this brick).
template <int Reach>
inline void mark_dependents(BrickMask& dirty, int n) {
  const int w = n >> 6;
  const std::uint64_t bit = std::uint64_t{1} << (n & 63);
  dirty.words[w] |= kSliceReach<Reach>.mask[n & 63];
  for (int r = 1; r <= Reach; ++r) {
    if (w - r >= 0) dirty.words[w - r] |= bit;
    if (w + r < 8) dirty.words[w + r] |= bit;
  }
}

// The voxels within `depth` of face f.
BrickMask face_layer(int f, int depth) {
  BrickMask m;
  for (int n = 0; n < kBrickVoxels; ++n) {
    const int c = (n >> (3 * (f >> 1))) & 7;
    if ((f & 1) ? c >= kBrickDim - depth : c < depth) m.set(n);
  }
  return m;
}

// One ordered Gauss-Seidel pass over the dirty free voxels: update(n) for each voxel n that
// is dirty when its turn comes, its dirty bit cleared first. order_mask is the free mask
// permuted for the ordering and x its flip_xor (bit position ^ x = voxel). update may mark
// voxels dirty; those later in the ordering are visited in the same pass.
template <typename Update>
inline void for_each_dirty(const BrickMask& order_mask, int x, BrickMask& dirty, Update&& update) {
  for (int w = 0; w < 8; ++w) {
    const std::uint64_t word = order_mask.words[w];
    // Nothing dirty in this slice now: nothing becomes dirty while it is visited either.
    if (word == 0 || dirty.words[(w << 6 ^ x) >> 6] == 0) continue;
    for (std::uint64_t m = word; m != 0; m &= m - 1) {
      const int n = ((w << 6) | std::countr_zero(m)) ^ x;
      if (!dirty.test(n)) continue;
      dirty.reset(n);
      update(n);
    }
  }
}

// A value moved by `change`: the brick's largest change, the faces whose neighbours read it
// (`faces`, from TileGeom<Reach>) and the voxels whose stencil holds it (dirty again).
template <int Reach>
inline void record_change(int n, float change, std::uint8_t faces, BrickMask& dirty, BrickPass& s) {
  s.max_change = std::max(s.max_change, change);
  s.changed_faces |= faces;
  mark_dependents<Reach>(dirty, n);
}

// First order: monotone (values only decrease, T = min(T, update)); a voxel's dependents
// are marked on any decrease. One ordered Gauss-Seidel sweep over the dirty free voxels.
void sweep_first(float* tile, const BrickMask& order_mask, int x, BrickMask& dirty, BrickPass& s) {
  constexpr int dy = TileGeom<1>::kDim, dz = dy * dy;
  for_each_dirty(order_mask, x, dirty, [&](int n) {
    const int t = kGeom1.tile_of[n];
    const float v = godunov(std::min(tile[t - 1], tile[t + 1]), std::min(tile[t - dy], tile[t + dy]),
                            std::min(tile[t - dz], tile[t + dz]));
    const float cur = tile[t];
    if (!(v < cur)) return;
    tile[t] = v;
    record_change<1>(n, cur - v, kGeom1.faces[n], dirty, s);
  });
}

// Second order on a signed tile: not monotone, so no min with the old value; dependents are
// marked when a value moves, by the tolerance or more.
void sweep_second(float* tile, const BrickMask& order_mask, int x, float tolerance, BrickMask& dirty,
                  BrickPass& s) {
  using G = TileGeom<2>;
  for_each_dirty(order_mask, x, dirty, [&](int n) {
    const int t = kGeom2.tile_of[n];
    const float cur = tile[t];
    const bool neg = std::signbit(cur);
    AxisTerm terms[3];
    for (int a = 0; a < 3; ++a) {
      const int st = G::kStride[a];
      const float l1 = std::abs(tile[t - st]), r1 = std::abs(tile[t + st]);
      const bool left = l1 <= r1;
      const float m1 = left ? l1 : r1;
      const float v2 = tile[left ? t - 2 * st : t + 2 * st];
      const float a2 = std::abs(v2);
      const float m2 = std::signbit(v2) == neg ? a2 : -a2;
      terms[a] = axis_term(m1, m2, a2 < kInf);
    }
    const float mag = solve_terms(terms[0], terms[1], terms[2]);
    const float old = std::abs(cur);
    tile[t] = neg ? -mag : mag;
    const float change = mag < old ? old - mag : mag - old;  // NaN (inf - inf) compares false
    if (!(change > 0.0f && change >= tolerance)) return;
    record_change<2>(n, change, kGeom2.faces[n], dirty, s);
  });
}

// Up to 8 ordered sweeps of one brick (fewer once no voxel is dirty) on a tile with the
// face neighbours' current values, starting with the pair `first` and its opposite. `dirty`
// persists between iterations.
BrickPass sweep_brick(RedistanceDomain& w, std::uint32_t b, const BrickMask& free_mask, BrickMask& dirty, bool second,
                       float tolerance, int first) {
  int order[8] = {first, first ^ 7};
  for (int k = 0, o = 2; k < 8; ++k)
    if (kOrderings[k] != first && kOrderings[k] != (first ^ 7)) order[o++] = kOrderings[k];
  BrickPass s;
  float* own = w.values(b);
  auto pending = [&] {
    std::uint64_t any = 0;
    for (int k = 0; k < 8; ++k) any |= (dirty.words[k] &= free_mask.words[k]);
    return any != 0;
  };
  if (!second) {
    alignas(64) float tile[TileGeom<1>::kVoxels];
    load_tile<1, false>(w, b, tile);
    for (int k = 0; k < 8 && pending(); ++k) {
      const int flip = order[k];
      sweep_first(tile, permute(free_mask, flip), flip_xor(flip), dirty, s);
    }
    free_mask.for_each_set([&](int n) { own[n] = tile[kGeom1.tile_of[n]]; });
  } else {
    alignas(64) float tile[TileGeom<2>::kVoxels];
    load_tile<2, true>(w, b, tile);
    for (int k = 0; k < 8 && pending(); ++k) {
      const int flip = order[k];
      sweep_second(tile, permute(free_mask, flip), flip_xor(flip), tolerance, dirty, s);
    }
    free_mask.for_each_set([&](int n) { own[n] = std::abs(tile[kGeom2.tile_of[n]]); });
  }
  return s;
}

// Per brick, the ordering to sweep first: along increasing distance from the interface
// voxels, judged from their centroid against the brick's centre (from the face neighbours
// holding interface voxels when the brick holds none). Information then crosses the brick in
// its first sweep; with a fixed first ordering, bricks whose characteristics run the other
// way took every ordering, each re-marking the voxels it changed (Table 5.1's sphere at
// N = 256, W = 6: 8.6 -> 5.0 evaluations per voxel). The pair's opposite, swept second,
// serves the other side of the zero level. Only the order of the sweeps changes.
std::vector<std::uint8_t> first_orderings(const RedistanceDomain& w) {
  std::vector<std::uint8_t> first(w.size(), 0);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, w.size(), 256), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t b = r.begin(); b != r.end(); ++b) {
      int c[3] = {0, 0, 0};  // twice the centroid offset, summed
      w.fixed[b].for_each_set([&](int v) {
        for (int a = 0; a < 3; ++a) c[a] += 2 * ((v >> (3 * a)) & 7) - (kBrickDim - 1);
      });
      if (w.fixed[b].none())
        for (int f = 0; f < 6; ++f) {
          const std::uint32_t nb = w.nbr[b][std::size_t(f)];
          if (nb != kNoBrick && !w.fixed[nb].none()) c[f >> 1] += (f & 1) ? 1 : -1;
        }
      int flip = 0;  // bit a: sweep axis a downward (the interface lies above the centre)
      for (int a = 0; a < 3; ++a)
        if (c[a] > 0) flip |= 1 << a;
      first[b] = std::uint8_t(flip);
    }
  });
  return first;
}

}  // namespace

// Sweeps bricks with work (brick_rounds) until a round's largest change is below the
// tolerance, nothing is left to do, or `max_iterations` ran. Returns iterations.
int sweep(RedistanceDomain& w, int order, int max_iterations, float tolerance, const ProgressHook& progress) {
  const bool second = order == 2;
  const int reach = second ? 2 : 1;
  const std::vector<BrickMask> free_mask = free_masks(w);
  std::vector<BrickMask> dirty = free_mask;
  const std::vector<std::uint8_t> first = first_orderings(w);
  BrickMask layers[6];
  for (int f = 0; f < 6; ++f) layers[f] = face_layer(f, reach);
  return brick_rounds(w, free_mask, max_iterations, tolerance, "redistance sweep", progress,
                      [&](std::uint32_t b, std::uint8_t bits) {
                        for (int f = 0; f < 6; ++f)
                          if (bits >> f & 1)
                            for (int k = 0; k < 8; ++k) dirty[b].words[k] |= layers[f].words[k];
                        BrickPass s = sweep_brick(w, b, free_mask[b], dirty[b], second, tolerance, first[b]);
                        s.more_work = !dirty[b].none();
                        return s;
                      });
}

}  // namespace levelset::detail
