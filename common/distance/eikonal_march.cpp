#include "distance/eikonal_march.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "distance/eikonal_rounds.hpp"
#include "distance/eikonal_trial_heap.hpp"
#include "distance/eikonal_update.hpp"
#include "distance/redistance_tile.hpp"

namespace levelset::detail {

namespace {

// Per tile voxel: its input sign, whether it is an interface voxel, whether the march may set
// it (a free voxel of the brick itself), whether its value is known (fixed and boundary
// voxels from the start, the brick's own when accepted) and whether it waits in the heap.
enum : std::uint8_t { kInsideBit = 1, kFixedBit = 2, kFreeBit = 4, kKnownBit = 8, kTrialBit = 16 };

template <int Halo>
struct MarchTile {
  using G = TileGeom<Halo>;
  alignas(64) float val[G::kVoxels];
  alignas(64) std::uint8_t st[G::kVoxels];
  alignas(64) float cap[G::kVoxels];  // the free voxels' limits
};

// Upwind update of tile voxel t from the known voxels on its own side of the interface and
// the fixed ones (a side's march never reads the other side's free voxels). Second order:
// the next value along the same direction, signed relative to the voxel.
template <int Halo>
inline float tile_update(const MarchTile<Halo>& m, int t, bool second) {
  using G = TileGeom<Halo>;
  const std::uint8_t side = m.st[t] & kInsideBit;
  auto usable = [&](int u) {
    const std::uint8_t s = m.st[u];
    return (s & kKnownBit) && ((s & kInsideBit) == side || (s & kFixedBit));
  };
  AxisTerm terms[3];
  for (int a = 0; a < 3; ++a) {
    const int st = G::kStride[a];
    float m1 = kInf, m2 = kInf;
    for (int dir : {-st, st}) {
      const int t1 = t + dir;
      if (!usable(t1) || !(m.val[t1] < m1)) continue;
      m1 = m.val[t1];
      m2 = kInf;
      if constexpr (Halo >= 2) {
        const int t2 = t1 + dir;
        if (second && usable(t2)) m2 = (m.st[t2] & kInsideBit) == side ? m.val[t2] : -m.val[t2];
      }
    }
    terms[a] = axis_term(m1, m2, second && std::abs(m2) < kInf);
  }
  return solve_terms(terms[0], terms[1], terms[2]);
}

// Whether the brick across face f of brick b may read voxel n of b (within Halo voxels of
// the face), now or before a change, with lo = the smaller of its old and new value. Only
// the voxel adjacent to the face on the same line reads it (depth 0 as its upwind neighbour,
// depth 1 as the next value behind that one), and only when it is upwind of that voxel's
// value: at most that value. (The voxel behind the adjacent one reads depth 0 as a next
// value only when it continues monotonically, i.e. at most the adjacent voxel's value.)
// The neighbour's values are read while no kernel writes them (it is of the other colour).
// A change that nobody reads needs no re-march.
bool neighbour_reads(const RedistanceDomain& w, std::uint32_t b, int n, int f, float lo) {
  const std::uint32_t nb = w.nbr[b][f];
  if (nb == kNoBrick) return false;
  const int shift = 3 * (f >> 1);
  const int adjacent = (f & 1) ? 0 : kBrickDim - 1;  // the neighbour's coordinate next to the face
  return lo <= w.values(nb)[(n & ~(7 << shift)) | adjacent << shift];
}

// Fast marching inside brick b (see march() in the header): the tile holds the brick's fixed
// voxels and its face neighbours' current values (`Halo` layers deep) as boundary data, known
// from the start and never changed. The brick's free voxels are recomputed from scratch; the
// result says which faces' neighbours read a value that changed.
template <int Halo>
BrickPass march_brick(RedistanceDomain& w, std::uint32_t b, const BrickMask& free_mask, bool second, float limit,
                      float tolerance, TrialHeap& scratch) {
  using G = TileGeom<Halo>;
  MarchTile<Halo> m;
  std::fill(m.val, m.val + G::kVoxels, kInf);
  std::fill(m.st, m.st + G::kVoxels, std::uint8_t{0});
  const float* cap = w.cap.empty() ? nullptr : w.cap.data() + std::size_t(b) * kBrickVoxels;
  TrialHeap& heap = scratch;
  heap.clear();
  auto put = [&](std::uint32_t src, int n, int t, bool own) {
    std::uint8_t s = w.inside[src].test(n) ? kInsideBit : 0;
    const float v = w.values(src)[n];
    if (w.fixed[src].test(n)) {
      s |= kFixedBit | kKnownBit;
      m.val[t] = v;
    } else if (own) {
      if (free_mask.test(n)) s |= kFreeBit;
      m.cap[t] = cap != nullptr ? std::min(limit, cap[n]) : limit;
    } else if (v <= limit) {
      s |= kKnownBit;
      m.val[t] = v;
    }
    m.st[t] = s;
  };
  for (int n = 0; n < kBrickVoxels; ++n) put(b, n, kTileGeom<Halo>.tile_of[n], true);
  for_each_halo_voxel<Halo>(w.nbr[b], [&](std::uint32_t nb, int n, int t) { put(nb, n, t, false); });
  // A better tentative value v for free voxel t.
  auto offer = [&](int t, float v) {
    if (!(v < m.val[t]) || !(v <= m.cap[t])) return;
    m.val[t] = v;
    const std::uint64_t k = trial_key(v, t);
    if (m.st[t] & kTrialBit) {
      heap.decrease(k);
    } else {
      m.st[t] |= kTrialBit;
      heap.push(k);
    }
  };
  // The front: free voxels next to a fixed or a halo voxel, from those alone.
  free_mask.for_each_set([&](int n) {
    const int t = kTileGeom<Halo>.tile_of[n];
    for (int a = 0; a < 3; ++a)
      if ((m.st[t - G::kStride[a]] | m.st[t + G::kStride[a]]) & kKnownBit) {
        offer(t, tile_update(m, t, second));
        return;
      }
  });
  while (!heap.empty()) {
    const int t = key_tile(heap.pop());
    m.st[t] = std::uint8_t((m.st[t] & ~kTrialBit) | kKnownBit);
    const std::uint8_t side = m.st[t] & kInsideBit;
    for (int a = 0; a < 3; ++a)
      for (int dir : {-G::kStride[a], G::kStride[a]}) {
        const int t2 = t + dir;
        const std::uint8_t s2 = m.st[t2];
        if ((s2 & (kFreeBit | kKnownBit)) != kFreeBit || (s2 & kInsideBit) != side) continue;
        offer(t2, tile_update(m, t2, second));
      }
  }
  BrickPass pass;
  float* own = w.values(b);
  free_mask.for_each_set([&](int n) {
    const int t = kTileGeom<Halo>.tile_of[n];
    const float v = (m.st[t] & kKnownBit) ? m.val[t] : kInf;
    const float old = own[n];
    own[n] = v;
    if (v == old) return;
    const float change = (v == kInf || old == kInf) ? kInf : std::abs(v - old);
    if (!(change >= tolerance)) return;
    pass.max_change = std::max(pass.max_change, change);
    const float lo = std::min(v, old);
    for (std::uint8_t faces = kTileGeom<Halo>.faces[n]; faces != 0; faces &= std::uint8_t(faces - 1)) {
      const int f = std::countr_zero(faces);
      if (neighbour_reads(w, b, n, f, lo)) pass.changed_faces |= std::uint8_t(1u << f);
    }
  });
  return pass;
}

}  // namespace

int march(RedistanceDomain& w, int order, double limit, float tolerance, const ProgressHook& progress) {
  const bool second = order == 2;
  const std::vector<BrickMask> free_mask = free_masks(w);
  const float lim = float(limit);
  return brick_rounds(w, free_mask, kMaxMarchRounds, tolerance, "redistance march", progress,
                      [&](std::uint32_t b, std::uint8_t) {
                        thread_local TrialHeap scratch;
                        return second ? march_brick<2>(w, b, free_mask[b], true, lim, tolerance, scratch)
                                      : march_brick<1>(w, b, free_mask[b], false, lim, tolerance, scratch);
                      });
}

}  // namespace levelset::detail
