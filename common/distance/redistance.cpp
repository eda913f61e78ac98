#include "distance/redistance.hpp"

#include <algorithm>
#include <array>
#include <atomic>
#include <bit>
#include <chrono>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "core/error.hpp"
#include "grid/band_builder.hpp"
#include "grid/tile.hpp"

namespace levelset {

namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr std::size_t kMaxBricks = std::size_t{1} << 23;  // voxel ids b*512+n fit in 32 bits

// ---------------------------------------------------------------------------------------
// sqrt(max(x, 0)); a NaN (inf - inf in a candidate that is not selected) gives 0 without the
// libm errno path.
inline float sqrt_nonneg(float x) { return std::sqrt(x > 0.0f ? x : 0.0f); }

// Godunov upwind update of |grad T| = 1 with h = 1 (thesis 2.28 / 4.4): the smallest root
// of sum_a max(T - m_a, 0)^2 = 1, where m_a is the smaller neighbour value along axis a.
// Only neighbours below the result take part; +inf neighbours never do. The one-, two- and
// three-axis candidates are all formed (relative to the smallest value, so large distances
// lose no precision) and the first one that stays upwind is selected.
inline float godunov(float a, float b, float c) {
  const float lo = std::min(a, b), hi = std::max(a, b);
  const float s0 = std::min(lo, c), mid = std::max(lo, c);
  const float s1 = std::min(hi, mid), s2 = std::max(hi, mid);
  const float p = s1 - s0, q = s2 - s0;
  const float t2 = 0.5f * (p + sqrt_nonneg(2.0f - p * p));
  const float pq = p + q;
  const float t3 = (pq + sqrt_nonneg(pq * pq - 3.0f * (p * p + q * q - 1.0f))) * (1.0f / 3.0f);
  const float t = 1.0f <= p ? 1.0f : (t2 <= q ? t2 : t3);
  return s0 < kInf ? s0 + t : kInf;
}

// ---------------------------------------------------------------------------------------
// Brick-mask morphology: one-voxel dilation along one axis, across brick faces.
// Mask layout (brick_mask.hpp): word = z-slice, byte = y-row, bit = x.
constexpr std::uint64_t kCol0 = 0x0101010101010101ull;  // x = 0
constexpr std::uint64_t kCol7 = 0x8080808080808080ull;  // x = 7
constexpr std::uint64_t kRow0 = 0x00000000000000ffull;  // y = 0
constexpr std::uint64_t kRow7 = 0xff00000000000000ull;  // y = 7

bool face_layer_set(const BrickMask& m, int axis, bool plus) {
  if (axis == 2) return m.words[plus ? 7 : 0] != 0;
  const std::uint64_t sel = axis == 0 ? (plus ? kCol7 : kCol0) : (plus ? kRow7 : kRow0);
  for (std::uint64_t w : m.words)
    if (w & sel) return true;
  return false;
}

BrickMask dilate_along(const BrickMask& m, const BrickMask* minus, const BrickMask* plus, int axis) {
  BrickMask r;
  for (int w = 0; w < 8; ++w) {
    std::uint64_t v = m.words[w];
    if (axis == 0) {
      v |= ((v << 1) & ~kCol0) | ((v >> 1) & ~kCol7);
      if (minus) v |= (minus->words[w] & kCol7) >> 7;
      if (plus) v |= (plus->words[w] & kCol0) << 7;
    } else if (axis == 1) {
      v |= (v << 8) | (v >> 8);
      if (minus) v |= minus->words[w] >> 56;
      if (plus) v |= plus->words[w] << 56;
    } else {
      if (w > 0) v |= m.words[w - 1];
      else if (minus) v |= minus->words[7];
      if (w < 7) v |= m.words[w + 1];
      else if (plus) v |= plus->words[0];
    }
    r.words[w] = v;
  }
  return r;
}

// Bricks sorted by key with one mask each; lookups by binary search.
struct BrickSet {
  std::vector<Coord> coords;
  std::vector<std::uint64_t> keys;
  std::vector<BrickMask> masks;

  std::uint32_t find(const Coord& c) const {
    if (!brick_in_range(c)) return kNoBrick;
    const std::uint64_t k = brick_key(c);
    const auto it = std::lower_bound(keys.begin(), keys.end(), k);
    return it != keys.end() && *it == k ? std::uint32_t(it - keys.begin()) : kNoBrick;
  }
};

Coord unit(int axis, int s) {
  Coord d{0, 0, 0};
  d[axis] = s;
  return d;
}

// One-voxel dilation of every mask along `axis` (both directions), allocating bricks the
// dilation reaches.
void dilate_once(BrickSet& set, int axis) {
  std::vector<Coord> extra;
  for (std::size_t b = 0; b < set.coords.size(); ++b) {
    for (int s = -1; s <= 1; s += 2) {
      if (!face_layer_set(set.masks[b], axis, s > 0)) continue;
      const Coord c = set.coords[b] + unit(axis, s);
      if (!brick_in_range(c))
        throw Error(ErrorCode::LimitExceeded, "redistance",
                    "growing the band leaves the index range");
      if (set.find(c) == kNoBrick) extra.push_back(c);
    }
  }
  if (!extra.empty()) {
    std::sort(extra.begin(), extra.end(),
              [](const Coord& a, const Coord& b) { return brick_key(a) < brick_key(b); });
    extra.erase(std::unique(extra.begin(), extra.end()), extra.end());
    if (set.coords.size() + extra.size() > kMaxBricks)
      throw Error(ErrorCode::LimitExceeded, "redistance", "domain exceeds 2^23 bricks");
    BrickSet merged;
    const std::size_t n = set.coords.size() + extra.size();
    merged.coords.reserve(n);
    merged.keys.reserve(n);
    merged.masks.reserve(n);
    std::size_t i = 0, j = 0;
    while (i < set.coords.size() || j < extra.size()) {
      const bool take_old =
          j == extra.size() || (i < set.coords.size() && set.keys[i] < brick_key(extra[j]));
      if (take_old) {
        merged.coords.push_back(set.coords[i]);
        merged.keys.push_back(set.keys[i]);
        merged.masks.push_back(set.masks[i]);
        ++i;
      } else {
        merged.coords.push_back(extra[j]);
        merged.keys.push_back(brick_key(extra[j]));
        merged.masks.push_back(BrickMask{});
        ++j;
      }
    }
    set = std::move(merged);
  }
  std::vector<BrickMask> out(set.coords.size());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, set.coords.size(), 64),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      for (std::size_t b = r.begin(); b != r.end(); ++b) {
                        const std::uint32_t lo = set.find(set.coords[b] + unit(axis, -1));
                        const std::uint32_t hi = set.find(set.coords[b] + unit(axis, 1));
                        out[b] = dilate_along(set.masks[b], lo == kNoBrick ? nullptr : &set.masks[lo],
                                              hi == kNoBrick ? nullptr : &set.masks[hi], axis);
                      }
                    });
  set.masks = std::move(out);
}

// ---------------------------------------------------------------------------------------
// The computational domain: bricks sorted by key, dense unsigned distances in voxels.
struct Work {
  std::vector<Coord> coords;
  std::vector<std::array<std::uint32_t, 6>> nbr;  // face neighbours, kNoBrick if none
  std::vector<std::uint32_t> source;              // input brick or kNoBrick
  std::vector<BrickMask> domain;                  // voxels to compute
  std::vector<BrickMask> fixed;                   // interface voxels (never updated)
  std::vector<BrickMask> inside;                  // input sign of every voxel
  std::vector<float> dist;                        // 512 per brick; +inf = unknown

  std::size_t size() const { return coords.size(); }
  float* values(std::uint32_t b) { return dist.data() + std::size_t(b) * kBrickVoxels; }
  const float* values(std::uint32_t b) const { return dist.data() + std::size_t(b) * kBrickVoxels; }
};

Work build_domain(const NarrowBand& in, int grow, const ProgressHook& progress) {
  BrickSet set;
  const auto bricks = in.bricks();
  set.coords.reserve(bricks.size());
  for (const Brick& br : bricks) {
    set.coords.push_back(br.coord);
    set.keys.push_back(brick_key(br.coord));
    set.masks.push_back(br.active);
  }
  for (int k = 0; k < grow; ++k) {
    for (int axis = 0; axis < 3; ++axis) dilate_once(set, axis);
    progress.check("redistance");
  }
  if (set.coords.size() > kMaxBricks)
    throw Error(ErrorCode::LimitExceeded, "redistance", "domain exceeds 2^23 bricks");

  Work w;
  const std::size_t n = set.coords.size();
  w.coords = set.coords;
  w.domain = std::move(set.masks);
  w.nbr.resize(n);
  w.source.resize(n);
  w.fixed.assign(n, BrickMask{});
  w.inside.resize(n);
  w.dist.assign(n * kBrickVoxels, kInf);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 32), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t b = r.begin(); b != r.end(); ++b) {
      const Coord c = set.coords[b];
      for (int f = 0; f < 6; ++f) w.nbr[b][f] = set.find(c + unit(f >> 1, (f & 1) ? 1 : -1));
      const std::uint32_t src = grow == 0 ? std::uint32_t(b) : in.find_brick(c);
      w.source[b] = src;
      if (src != kNoBrick) {
        w.inside[b] = in.inside_mask(src);
        continue;
      }
      // A brick the input does not have: one sign per x-row (NarrowBand's row rule).
      BrickMask m;
      const Coord o = brick_origin(c);
      for (int z = 0; z < kBrickDim; ++z)
        for (int y = 0; y < kBrickDim; ++y)
          if (in.is_inside_unallocated(o + Coord{0, y, z})) m.words[z] |= std::uint64_t{0xff} << (8 * y);
      w.inside[b] = m;
    }
  });
  return w;
}

// ---------------------------------------------------------------------------------------
// Tile geometry for halo 1 (first order) and halo 2 (second order).
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
constexpr TileGeom<1> kGeom1{};
constexpr TileGeom<2> kGeom2{};

// ---------------------------------------------------------------------------------------
// Interface initialisation (see the header), from the input's values on a tile with a
// one-voxel halo.

// Activeness of the input's voxels on a halo-1 tile around brick src (1 = active).
void gather_active(const NarrowBand& in, std::uint32_t src, std::uint8_t* act) {
  const Coord self = in.bricks()[src].coord;
  const BrickMask* masks[27];
  for (int dz = -1; dz <= 1; ++dz)
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
        const std::uint32_t nb = (dx | dy | dz) == 0 ? src : in.find_brick(self + Coord{dx, dy, dz});
        masks[(dx + 1) + 3 * (dy + 1) + 9 * (dz + 1)] = nb == kNoBrick ? nullptr : &in.bricks()[nb].active;
      }
  for (int z = -1; z <= kBrickDim; ++z)
    for (int y = -1; y <= kBrickDim; ++y)
      for (int x = -1; x <= kBrickDim; ++x) {
        auto part = [](int c) { return c < 0 ? 0 : (c < kBrickDim ? 1 : 2); };
        const BrickMask* m = masks[part(x) + 3 * part(y) + 9 * part(z)];
        act[TileGeom<1>::index(x, y, z)] = m != nullptr && m->test(local_index(x & 7, y & 7, z & 7));
      }
}

// Unsigned subcell distance (voxels) of an interface voxel at tile index t; see the header.
// d_C: distance to the plane through the edge crossings (inverse crossing distances on
// crossing axes, |du/dx_a|/|u| elsewhere) - robust, exact for linear u, first order in the
// surface's curvature. d_T: second-order Taylor along the normal, u = g d - (u_nn/2) d^2,
// from central first and second differences - exact for distance fields and for u whose
// gradient varies along the normal, but it needs a full 3x3x3 stencil of active values on
// one side of every crossing. d_T is used where it exists and agrees with d_C to 0.1 voxel;
// the result never exceeds the nearest crossing.
double subcell_distance(const float* tile, const std::uint8_t* act, int t) {
  constexpr int S[3] = {TileGeom<1>::kStride[0], TileGeom<1>::kStride[1], TileGeom<1>::kStride[2]};
  const double u = tile[t];
  if (u == 0.0) return 0.0;
  const bool in_u = tile[t] < 0.0f;
  double gsum = 0.0, gmax = 0.0;
  bool full = true;  // every face neighbour active, no axis crossed on both sides
  for (int a = 0; a < 3; ++a) {
    const double um = tile[t - S[a]], up = tile[t + S[a]];
    const bool cm = (tile[t - S[a]] < 0.0f) != in_u, cp = (tile[t + S[a]] < 0.0f) != in_u;
    const bool am = act[t - S[a]] != 0, ap = act[t + S[a]] != 0;
    full &= am && ap && !(cm && cp);
    double g = 0.0;
    if (cm || cp) {
      // Inverse crossing distance 1/theta = (u - u_j)/u >= 1; the nearer crossing wins.
      if (cm) g = std::max(g, (u - um) / u);
      if (cp) g = std::max(g, (u - up) / u);
      gmax = std::max(gmax, g);
    } else if (am && ap) {
      g = std::abs(up - um) / (2.0 * std::abs(u));
    } else if (am) {
      g = std::abs(u - um) / std::abs(u);
    } else if (ap) {
      g = std::abs(up - u) / std::abs(u);
    }
    gsum += g * g;
  }
  const double d_plane = 1.0 / std::sqrt(gsum);  // gsum >= 1: at most 1 voxel
  const double nearest = 1.0 / gmax;             // distance to the nearest crossing
  if (!full) return d_plane;
  for (int a = 0; a < 3; ++a)
    for (int b = a + 1; b < 3; ++b)
      for (int s = -1; s <= 1; s += 2)
        for (int r = -1; r <= 1; r += 2)
          if (!act[t + s * S[a] + r * S[b]]) return d_plane;
  double g[3], H[3][3];
  for (int a = 0; a < 3; ++a) {
    g[a] = 0.5 * (double(tile[t + S[a]]) - double(tile[t - S[a]]));
    H[a][a] = double(tile[t + S[a]]) - 2.0 * u + double(tile[t - S[a]]);
    for (int b = a + 1; b < 3; ++b) {
      H[a][b] = H[b][a] = 0.25 * (double(tile[t + S[a] + S[b]]) - double(tile[t + S[a] - S[b]]) -
                                  double(tile[t - S[a] + S[b]]) + double(tile[t - S[a] - S[b]]));
    }
  }
  const double g2 = g[0] * g[0] + g[1] * g[1] + g[2] * g[2];
  if (!(g2 > 0.0)) return d_plane;
  double unn = 0.0;
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b) unn += g[a] * H[a][b] * g[b];
  unn /= g2;
  const double gn = std::sqrt(g2);
  const double disc = g2 - 2.0 * unn * u;  // g^2 - 4 (u_nn/2) u
  if (!(disc > 0.0)) return d_plane;
  const double d_taylor = std::abs(2.0 * u / (gn + std::sqrt(disc)));
  if (!(std::abs(d_taylor - d_plane) <= 0.1)) return d_plane;
  return std::min(d_taylor, nearest);
}

std::uint64_t init_interface(const NarrowBand& in, Work& w) {
  std::vector<std::uint32_t> work_of_input;  // input bricks that hold active voxels
  for (std::uint32_t b = 0; b < w.size(); ++b)
    if (w.source[b] != kNoBrick && !in.bricks()[w.source[b]].active.none()) work_of_input.push_back(b);
  std::vector<std::uint32_t> counts(work_of_input.size(), 0);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, work_of_input.size(), 8), [&](const tbb::blocked_range<std::size_t>& r) {
    std::vector<float> tile(TileGeom<1>::kVoxels);
    std::vector<std::uint8_t> act(TileGeom<1>::kVoxels);
    for (std::size_t i = r.begin(); i != r.end(); ++i) {
      const std::uint32_t b = work_of_input[i];
      const std::uint32_t src = w.source[b];
      gather_tile(in, src, 1, tile);
      gather_active(in, src, act.data());
      float* dist = w.values(b);
      BrickMask& fixed = w.fixed[b];
      std::uint32_t count = 0;
      in.bricks()[src].active.for_each_set([&](int n) {
        const int t = kGeom1.tile_of[n];
        const bool in_u = tile[t] < 0.0f;
        bool crossing = false;
        for (int a = 0; a < 3; ++a) {
          const int st = TileGeom<1>::kStride[a];
          crossing |= ((tile[t - st] < 0.0f) != in_u) | ((tile[t + st] < 0.0f) != in_u);
        }
        if (!crossing) return;
        dist[n] = static_cast<float>(subcell_distance(tile.data(), act.data(), t));
        fixed.set(n);
        ++count;
      });
      counts[i] = count;
    }
  });
  std::uint64_t total = 0;
  for (std::uint32_t c : counts) total += c;
  return total;
}

// ---------------------------------------------------------------------------------------
// Second-order upwind update: the largest root of sum_a alpha2_a (T - beta_a)^2 = 1 with
// the axes taken in increasing beta while they stay upwind (beta_a < T). A first-order axis
// has alpha2 = 1, beta = m1 (the smaller neighbour); a second-order axis, where the next
// value m2 along the same side continues monotonically (m2 <= m1), has the one-sided
// difference (3T - 4m1 + m2)/2: alpha2 = 9/4, beta = (4m1 - m2)/3. m2 is signed relative to
// the voxel, so a stencil may reach across the zero level to a fixed interface voxel.
constexpr float kAlpha2Second = 2.25f;

struct AxisTerm {
  float beta = kInf;
  float alpha2 = 1.0f;
};

inline AxisTerm axis_term(float m1, float m2, bool second_order) {
  const bool second = second_order && m2 <= m1;
  return {second ? (4.0f * m1 - m2) * (1.0f / 3.0f) : m1, second ? kAlpha2Second : 1.0f};
}

inline void order_terms(AxisTerm& x, AxisTerm& y) {
  const bool swap = y.beta < x.beta;
  const AxisTerm lo = swap ? y : x, hi = swap ? x : y;
  x = lo;
  y = hi;
}

// Like godunov(): candidates with one, two and three axes, relative to the smallest beta.
inline float solve_terms(AxisTerm t0, AxisTerm t1, AxisTerm t2) {
  order_terms(t0, t1);
  order_terms(t1, t2);
  order_terms(t0, t1);
  const float b0 = t0.beta, p = t1.beta - b0, q = t2.beta - b0;
  // 1/A from the number of second-order axes (a division would stall the chain).
  static constexpr float kInv2[3] = {1.0f / 2.0f, 1.0f / 3.25f, 1.0f / 4.5f};
  static constexpr float kInv3[4] = {1.0f / 3.0f, 1.0f / 4.25f, 1.0f / 5.5f, 1.0f / 6.75f};
  const int s0 = t0.alpha2 > 1.0f, s1 = t1.alpha2 > 1.0f, s2 = t2.alpha2 > 1.0f;
  const float T1 = s0 ? 2.0f / 3.0f : 1.0f;  // 1 / sqrt(alpha2)
  const float A2 = t0.alpha2 + t1.alpha2, B2 = t1.alpha2 * p, C2 = t1.alpha2 * p * p - 1.0f;
  const float T2 = (B2 + sqrt_nonneg(B2 * B2 - A2 * C2)) * kInv2[s0 + s1];
  const float A3 = A2 + t2.alpha2, B3 = B2 + t2.alpha2 * q, C3 = C2 + t2.alpha2 * q * q;
  const float T3 = (B3 + sqrt_nonneg(B3 * B3 - A3 * C3)) * kInv3[s0 + s1 + s2];
  const float T = T1 <= p ? T1 : (T2 <= q ? T2 : T3);
  return b0 < kInf ? b0 + T : kInf;
}

// ---------------------------------------------------------------------------------------
// Fast sweeping, brick by brick, on dense tiles with a halo from the face neighbours.

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
void load_tile(const Work& w, std::uint32_t b, float* tile) {
  using G = TileGeom<Halo>;
  std::fill(tile, tile + G::kVoxels, kInf);
  auto put = [&](std::uint32_t src, int sx, int sy, int sz, int tx, int ty, int tz) {
    const int n = local_index(sx, sy, sz);
    const float v = w.values(src)[n];
    tile[G::index(tx, ty, tz)] = Signed && w.inside[src].test(n) ? -v : v;
  };
  for (int z = 0; z < kBrickDim; ++z)
    for (int y = 0; y < kBrickDim; ++y)
      for (int x = 0; x < kBrickDim; ++x) put(b, x, y, z, x, y, z);
  for (int f = 0; f < 6; ++f) {
    const std::uint32_t nb = w.nbr[b][f];
    if (nb == kNoBrick) continue;
    const int axis = f >> 1;
    for (int layer = 0; layer < Halo; ++layer) {
      const int mine = (f & 1) ? kBrickDim + layer : -1 - layer;  // tile coordinate on axis
      const int theirs = (f & 1) ? layer : kBrickDim - 1 - layer;
      for (int j = 0; j < kBrickDim; ++j)
        for (int i = 0; i < kBrickDim; ++i) {
          if (axis == 0) put(nb, theirs, i, j, mine, i, j);
          if (axis == 1) put(nb, i, theirs, j, i, mine, j);
          if (axis == 2) put(nb, i, j, theirs, i, j, mine);
        }
    }
  }
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

struct BrickSweep {
  float max_change = 0.0f;
  std::uint8_t changed_faces = 0;  // faces whose layers within the stencil reach changed
};

// First order: monotone (values only decrease, T = min(T, update)); a voxel's dependents
// are marked on any decrease. One ordered Gauss-Seidel sweep over the dirty free voxels.
void sweep_first(float* tile, const BrickMask& order_mask, int x, BrickMask& dirty, BrickSweep& s) {
  constexpr int dy = TileGeom<1>::kDim, dz = dy * dy;
  for (int w = 0; w < 8; ++w) {
    const std::uint64_t word = order_mask.words[w];
    // Nothing dirty in this slice now: nothing becomes dirty while it is visited either.
    if (word == 0 || dirty.words[(w << 6 ^ x) >> 6] == 0) continue;
    for (std::uint64_t m = word; m != 0; m &= m - 1) {
      const int n = ((w << 6) | std::countr_zero(m)) ^ x;
      if (!dirty.test(n)) continue;
      dirty.reset(n);
      const int t = kGeom1.tile_of[n];
      const float v = godunov(std::min(tile[t - 1], tile[t + 1]), std::min(tile[t - dy], tile[t + dy]),
                              std::min(tile[t - dz], tile[t + dz]));
      const float cur = tile[t];
      if (!(v < cur)) continue;
      tile[t] = v;
      s.max_change = std::max(s.max_change, cur - v);
      s.changed_faces |= kGeom1.faces[n];
      mark_dependents<1>(dirty, n);
    }
  }
}

// Second order on a signed tile: not monotone, so no min with the old value; dependents are
// marked when a value moves, by the tolerance or more.
void sweep_second(float* tile, const BrickMask& order_mask, int x, float tolerance, BrickMask& dirty,
                  BrickSweep& s) {
  using G = TileGeom<2>;
  for (int w = 0; w < 8; ++w) {
    const std::uint64_t word = order_mask.words[w];
    // Nothing dirty in this slice now: nothing becomes dirty while it is visited either.
    if (word == 0 || dirty.words[(w << 6 ^ x) >> 6] == 0) continue;
    for (std::uint64_t m = word; m != 0; m &= m - 1) {
      const int n = ((w << 6) | std::countr_zero(m)) ^ x;
      if (!dirty.test(n)) continue;
      dirty.reset(n);
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
      if (!(change > 0.0f && change >= tolerance)) continue;
      s.max_change = std::max(s.max_change, change);
      s.changed_faces |= kGeom2.faces[n];
      mark_dependents<2>(dirty, n);
    }
  }
}

// Up to 8 ordered sweeps of one brick (fewer once no voxel is dirty) on a tile with the
// face neighbours' current values. `dirty` persists between iterations.
BrickSweep sweep_brick(Work& w, std::uint32_t b, const BrickMask& free_mask, BrickMask& dirty, bool second,
                       float tolerance) {
  BrickSweep s;
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
      const int flip = kOrderings[k];
      sweep_first(tile, permute(free_mask, flip), flip_xor(flip), dirty, s);
    }
    free_mask.for_each_set([&](int n) { own[n] = tile[kGeom1.tile_of[n]]; });
  } else {
    alignas(64) float tile[TileGeom<2>::kVoxels];
    load_tile<2, true>(w, b, tile);
    for (int k = 0; k < 8 && pending(); ++k) {
      const int flip = kOrderings[k];
      sweep_second(tile, permute(free_mask, flip), flip_xor(flip), tolerance, dirty, s);
    }
    free_mask.for_each_set([&](int n) { own[n] = std::abs(tile[kGeom2.tile_of[n]]); });
  }
  return s;
}

// Sweeps bricks with work in two checkerboard colours until an iteration's largest change is
// below the tolerance, nothing is left to do, or `max_iterations` ran. Returns iterations.
int sweep(Work& w, int order, int max_iterations, float tolerance, const ProgressHook& progress) {
  const std::size_t n = w.size();
  const bool second = order == 2;
  const int reach = second ? 2 : 1;
  std::vector<BrickMask> free_mask(n), dirty(n);
  std::vector<std::uint32_t> colour[2];
  for (std::uint32_t b = 0; b < n; ++b) {
    for (int k = 0; k < 8; ++k) free_mask[b].words[k] = w.domain[b].words[k] & ~w.fixed[b].words[k];
    if (free_mask[b].none()) continue;
    dirty[b] = free_mask[b];
    const Coord c = w.coords[b];
    colour[(c.x + c.y + c.z) & 1].push_back(b);
  }
  BrickMask layers[6];
  for (int f = 0; f < 6; ++f) layers[f] = face_layer(f, reach);
  // Per brick: bit f = the neighbour across face f changed its layer there; bit 6 = own work.
  constexpr std::uint8_t kOwnWork = 1u << 6;
  std::vector<std::atomic<std::uint8_t>> flags(n);
  for (auto& f : flags) f.store(kOwnWork, std::memory_order_relaxed);
  std::vector<float> change(n, 0.0f);
  int iterations = 0;
  while (iterations < max_iterations) {
    bool any = false;
    float max_change = 0.0f;
    for (int c = 0; c < 2; ++c) {
      const std::vector<std::uint32_t>& list = colour[c];
      tbb::parallel_for(tbb::blocked_range<std::size_t>(0, list.size(), 4), [&](const tbb::blocked_range<std::size_t>& r) {
        for (std::size_t i = r.begin(); i != r.end(); ++i) {
          const std::uint32_t b = list[i];
          change[b] = -1.0f;  // not swept
          const std::uint8_t bits = flags[b].exchange(0, std::memory_order_relaxed);
          if (bits == 0) continue;
          for (int f = 0; f < 6; ++f)
            if (bits >> f & 1)
              for (int k = 0; k < 8; ++k) dirty[b].words[k] |= layers[f].words[k];
          const BrickSweep s = sweep_brick(w, b, free_mask[b], dirty[b], second, tolerance);
          change[b] = s.max_change;
          if (!dirty[b].none()) flags[b].fetch_or(kOwnWork, std::memory_order_relaxed);
          for (int f = 0; f < 6; ++f) {
            const std::uint32_t nb = w.nbr[b][f];
            if ((s.changed_faces >> f & 1) && nb != kNoBrick)
              flags[nb].fetch_or(std::uint8_t(1u << (f ^ 1)), std::memory_order_relaxed);
          }
        }
      });
      for (std::uint32_t b : list) {
        if (change[b] < 0.0f) continue;
        any = true;
        max_change = std::max(max_change, change[b]);
      }
    }
    if (!any) break;
    ++iterations;
    progress.step(0.1 + 0.8 * double(iterations) / max_iterations, "redistance sweep");
    if (max_change < tolerance) break;
  }
  return iterations;
}

// ---------------------------------------------------------------------------------------
// Fast marching with a binary min-heap and lazy deletion.

// Face neighbour of voxel n of brick b in direction dir (Face order); false outside.
inline bool step(const Work& w, std::uint32_t& b, int& n, int dir) {
  const int shift = 3 * (dir >> 1);
  const int c = (n >> shift) & 7;
  if (c == ((dir & 1) ? 7 : 0)) {
    b = w.nbr[b][dir];
    n ^= 7 << shift;
    return b != kNoBrick;
  }
  n += (dir & 1) ? (1 << shift) : -(1 << shift);
  return true;
}

// Upwind update from the accepted neighbours (w.dist holds +inf for all others).
inline float known_update(const Work& w, std::uint32_t b, int n, bool second_order) {
  const bool inside = w.inside[b].test(n);
  AxisTerm terms[3];
  for (int a = 0; a < 3; ++a) {
    float m1 = kInf, m2 = kInf;
    for (int s = 0; s < 2; ++s) {
      std::uint32_t b1 = b;
      int n1 = n;
      if (!step(w, b1, n1, 2 * a + s)) continue;
      const float v1 = w.values(b1)[n1];
      if (!(v1 < m1)) continue;
      m1 = v1;
      m2 = kInf;
      if (second_order && step(w, b1, n1, 2 * a + s)) {
        const float v2 = w.values(b1)[n1];
        if (v2 < kInf) m2 = w.inside[b1].test(n1) == inside ? v2 : -v2;
      }
    }
    terms[a] = axis_term(m1, m2, second_order && std::abs(m2) < kInf);
  }
  return solve_terms(terms[0], terms[1], terms[2]);
}

struct HeapEntry {
  float value;
  std::uint32_t id;  // brick * 512 + voxel
};
struct HeapAfter {
  bool operator()(const HeapEntry& a, const HeapEntry& b) const {
    return a.value > b.value || (a.value == b.value && a.id > b.id);
  }
};

// The trial set: binary min-heaps, one per slice of the value range [0, limit] (a global
// heap over the whole front misses the cache on every level). The march only ever pops the
// smallest value, and every pushed value lands in the current slice or a later one, so the
// pop order is exactly that of one global heap. Values above the limit are never accepted
// and are not stored.
class TrialQueue {
 public:
  explicit TrialQueue(double limit)
      : limit_(limit),
        slices_(std::size_t(std::clamp(std::ceil(limit * kSlicesPerVoxel), 1.0, double(kMaxSlices)))),
        per_unit_(double(slices_.size()) / limit) {}

  void push(const HeapEntry& e) {
    if (!(double(e.value) <= limit_)) return;
    std::vector<HeapEntry>& h = slices_[slice_of(e.value)];
    h.push_back(e);
    std::push_heap(h.begin(), h.end(), HeapAfter{});
  }
  // Bulk insertion of the initial front.
  void assign(const std::vector<HeapEntry>& entries) {
    for (const HeapEntry& e : entries)
      if (double(e.value) <= limit_) slices_[slice_of(e.value)].push_back(e);
    for (auto& h : slices_) std::make_heap(h.begin(), h.end(), HeapAfter{});
  }
  bool pop(HeapEntry& e) {
    while (current_ < slices_.size() && slices_[current_].empty()) {
      slices_[current_].shrink_to_fit();
      ++current_;
    }
    if (current_ == slices_.size()) return false;
    std::vector<HeapEntry>& h = slices_[current_];
    std::pop_heap(h.begin(), h.end(), HeapAfter{});
    e = h.back();
    h.pop_back();
    return true;
  }

 private:
  static constexpr double kSlicesPerVoxel = 256.0;
  static constexpr std::size_t kMaxSlices = 1 << 16;
  std::size_t slice_of(float v) const {
    const double k = std::floor(double(v) * per_unit_);
    const std::size_t last = slices_.size() - 1;
    const std::size_t s = k <= 0.0 ? 0 : (k >= double(last) ? last : std::size_t(k));
    return std::max(s, current_);  // below the current slice (rounding): still the minimum
  }
  double limit_;
  std::vector<std::vector<HeapEntry>> slices_;
  double per_unit_;
  std::size_t current_ = 0;
};

void march(Work& w, int order, double limit, const ProgressHook& progress) {
  const std::size_t n = w.size();
  const bool second = order == 2;
  std::vector<float> tentative(w.dist.size(), kInf);
  // Initial front: free voxels next to an interface voxel, per brick in parallel.
  std::vector<std::vector<HeapEntry>> front(n);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 16), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t bi = r.begin(); bi != r.end(); ++bi) {
      const auto b = std::uint32_t(bi);
      const float* own = w.values(b);
      w.domain[b].for_each_set([&](int v) {
        if (own[v] < kInf) return;  // interface voxel
        bool near = false;
        for (int dir = 0; dir < 6 && !near; ++dir) {
          std::uint32_t b2 = b;
          int n2 = v;
          near = step(w, b2, n2, dir) && w.values(b2)[n2] < kInf;
        }
        if (!near) return;
        const float t = known_update(w, b, v, second);
        tentative[std::size_t(b) * kBrickVoxels + v] = t;
        front[b].push_back({t, b * std::uint32_t(kBrickVoxels) + std::uint32_t(v)});
      });
    }
  });
  TrialQueue trial(limit);
  {
    std::vector<HeapEntry> all;
    for (auto& f : front) all.insert(all.end(), f.begin(), f.end());
    front = {};
    trial.assign(all);
  }
  std::uint64_t pops = 0;
  HeapEntry e;
  while (trial.pop(e)) {
    if ((++pops & 0xffff) == 0) progress.check("redistance march");
    if (w.dist[e.id] < kInf) continue;  // accepted earlier with a smaller value
    w.dist[e.id] = e.value;
    const std::uint32_t b = e.id / kBrickVoxels;
    const int v = int(e.id % kBrickVoxels);
    for (int dir = 0; dir < 6; ++dir) {
      std::uint32_t b2 = b;
      int n2 = v;
      if (!step(w, b2, n2, dir) || !w.domain[b2].test(n2)) continue;
      const std::uint32_t id2 = b2 * std::uint32_t(kBrickVoxels) + std::uint32_t(n2);
      if (w.dist[id2] < kInf) continue;
      const float t = known_update(w, b2, n2, second);
      if (t < tentative[id2]) {
        tentative[id2] = t;
        trial.push({t, id2});
      }
    }
  }
}

// ---------------------------------------------------------------------------------------
// Output: voxels with distance <= W (voxels), signed by the input, in a new band.
NarrowBand assemble(const NarrowBand& in, const Work& w, const GridFrame& frame) {
  const std::size_t n = w.size();
  const double limit = frame.half_width;
  const double h = frame.voxel_size;
  std::vector<BrickMask> active(n);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 32), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t b = r.begin(); b != r.end(); ++b) {
      const float* d = w.values(std::uint32_t(b));
      BrickMask m = w.fixed[b];
      w.domain[b].for_each_set([&](int v) {
        if (double(d[v]) <= limit) m.set(v);
      });
      active[b] = m;
    }
  });
  // Bricks without active voxels are uniform in sign (band invariant) and dropped; the
  // output's row rule then gives their sign from the nearest kept brick of their x-row,
  // which is right because no sign change lies in between. A brick row with no kept brick
  // falls back to far_inside: keep one brick there when its sign differs.
  std::vector<std::uint8_t> keep(n, 0);
  for (std::size_t b = 0; b < n;) {
    std::size_t e = b;
    bool any = false;
    while (e < n && w.coords[e].y == w.coords[b].y && w.coords[e].z == w.coords[b].z) {
      keep[e] = !active[e].none();
      any |= keep[e] != 0;
      ++e;
    }
    if (!any && w.inside[b].test(0) != in.far_inside()) keep[b] = 1;
    b = e;
  }
  BandBuilder builder(frame);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 32), [&](const tbb::blocked_range<std::size_t>& r) {
    alignas(64) float dense[kBrickVoxels];
    for (std::size_t b = r.begin(); b != r.end(); ++b) {
      if (!keep[b]) continue;
      const float* d = w.values(std::uint32_t(b));
      active[b].for_each_set([&](int v) {
        const float mag = static_cast<float>(double(d[v]) * h);
        // Inside voxels stay strictly negative (a -0 would read as outside).
        dense[v] = w.inside[b].test(v) ? -std::max(mag, std::numeric_limits<float>::min()) : mag;
      });
      builder.add_brick(w.coords[b], active[b], w.inside[b], dense);
    }
  });
  return builder.finish(in.far_inside());
}

void validate(const RedistanceOptions& o) {
  if (!(o.half_width == 0.0 || (std::isfinite(o.half_width) && o.half_width >= 1.0)))
    throw Error(ErrorCode::InvalidArgument, "half_width",
                "must be 0 (keep the input's) or a finite width >= 1 voxel, got " +
                    std::to_string(o.half_width));
  if (o.max_sweep_iterations < 1)
    throw Error(ErrorCode::InvalidArgument, "max_sweep_iterations",
                "must be >= 1, got " + std::to_string(o.max_sweep_iterations));
  if (o.order != 1 && o.order != 2)
    throw Error(ErrorCode::InvalidArgument, "order", "must be 1 or 2, got " + std::to_string(o.order));
  if (!(std::isfinite(o.tolerance) && o.tolerance >= 0.0))
    throw Error(ErrorCode::InvalidArgument, "tolerance", "must be finite and >= 0");
}

}  // namespace

RedistanceResult redistance(const NarrowBand& in, const RedistanceOptions& options) {
  const auto t0 = std::chrono::steady_clock::now();
  validate(options);
  GridFrame frame = in.frame();
  if (options.half_width != 0.0) frame.half_width = options.half_width;
  RedistanceResult result{NarrowBand(frame), 0, 0, 0.0};  // validates the new frame
  result.band.set_far_inside(in.far_inside());
  options.progress.step(0.0, "redistance");
  if (in.brick_count() > 0) {
    const double grow = frame.half_width - in.half_width();
    Work w = build_domain(in, grow > 0.0 ? int(std::ceil(grow)) : 0, options.progress);
    result.interface_voxels = init_interface(in, w);
    options.progress.step(0.1, "redistance interface");
    if (options.method == RedistanceMethod::Sweep) {
      result.sweep_iterations = sweep(w, options.order, options.max_sweep_iterations,
                                      float(options.tolerance), options.progress);
    } else {
      march(w, options.order, frame.half_width, options.progress);
    }
    options.progress.step(0.9, "redistance assemble");
    result.band = assemble(in, w, frame);
  }
  options.progress.step(1.0, "redistance");
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return result;
}

}  // namespace levelset
