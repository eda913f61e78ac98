// Internal helpers shared by marching_cubes and surface_nets: tile strides, valid cells,
// per-brick slot bitmaps with O(1) rank, edge crossings with gradient normals, the fan choice,
// option checks and the batched parallel brick loop. Units: tile-local index space (voxel
// units relative to the brick origin). Threading: plain functions over per-thread data.
#pragma once

#include <array>
#include <bit>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <functional>
#include <limits>
#include <new>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#if defined(__SSE2__)
#include <immintrin.h>
#endif

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>

#include "core/error.hpp"
#include "core/huge_pages.hpp"
#include "core/progress.hpp"
#include "core/vec3.hpp"
#include "grid/narrow_band.hpp"
#include "surface/cell_tile.hpp"
#include "surface/surface_result.hpp"

namespace levelset::surface_detail {

inline constexpr int kTileStride[3] = {1, CellTile::kDim, CellTile::kDim * CellTile::kDim};
inline constexpr int kCornerOffset[8] = {
    0, 1, kTileStride[1], 1 + kTileStride[1], kTileStride[2], 1 + kTileStride[2],
    kTileStride[1] + kTileStride[2], 1 + kTileStride[1] + kTileStride[2]};

// Cells with min corner in [-1, 8)^3 whose 8 corners are all active.
struct ValidCells {
  static constexpr int kN = kBrickDim + 1;
  static int index(int x, int y, int z) { return (x + 1) + kN * ((y + 1) + kN * (z + 1)); }
  bool at(int x, int y, int z) const { return (valid_rows[std::size_t((y + 1) + kN * (z + 1))] >> (x + kH)) & 1u; }
  // Row bitmasks over x (bit x + kHalo) for every tile row (y, z): active and inside (< iso).
  static constexpr int kH = CellTile::kHalo;
  static int row(int y, int z) { return (y + kH) + CellTile::kDim * (z + kH); }
  std::array<std::uint32_t, CellTile::kDim * CellTile::kDim> active_rows{}, inside_rows{};
  // Per cell row (y, z) in [-1, 8)^2: valid cells and valid cells crossing iso (bit x + kHalo).
  std::array<std::uint32_t, kN * kN> valid_rows{}, mixed_rows{};
  int mixed_cells = 0;  // cells in [0, 8)^3 that are valid and cross iso
  // double(v) < iso  <=>  v < float_below(iso), the smallest float not below iso.
  static float float_below(double iso) {
    float below = float(iso);
    if (double(below) < iso) below = std::nextafter(below, std::numeric_limits<float>::infinity());
    return below;
  }
  void compute(const CellTile& t, double iso = 0.0) {
    active_rows = t.active_rows;
    const float below = float_below(iso);
    constexpr std::uint32_t kRowBits = (1u << CellTile::kDim) - 1;
    for (int r = 0; r < CellTile::kDim * CellTile::kDim; ++r) {
      const float* v = &t.values[std::size_t(r) * CellTile::kDim];
      std::uint32_t ins = 0;
#if defined(__SSE2__)
      const __m128 lim = _mm_set1_ps(below);
      for (int x = 0; x < CellTile::kDim; x += 4)  // reads into the next row / the padding
        ins |= std::uint32_t(_mm_movemask_ps(_mm_cmplt_ps(_mm_loadu_ps(v + x), lim))) << x;
      ins &= kRowBits;
#else
      for (int x = 0; x < CellTile::kDim; ++x) ins |= std::uint32_t(v[x] < below) << x;
#endif
      inside_rows[r] = ins;
    }
    compute_cells();
  }
  // The cell rows from active_rows and inside_rows (filled by the caller).
  void compute_cells() {
    mixed_cells = 0;
    constexpr std::uint32_t kCellBits = ((1u << kN) - 1) << (kH - 1);  // x in [-1, 8)
    for (int z = -1; z < kBrickDim; ++z)
      for (int y = -1; y < kBrickDim; ++y) {
        const int r = row(y, z);
        constexpr int D = CellTile::kDim;
        std::uint32_t v = active_rows[r] & active_rows[r + 1] & active_rows[r + D] & active_rows[r + D + 1];
        v &= v >> 1;
        v &= kCellBits;
        const std::uint32_t i0 = inside_rows[r], i1 = inside_rows[r + 1], i2 = inside_rows[r + D],
                            i3 = inside_rows[r + D + 1];
        std::uint32_t o = i0 | i1 | i2 | i3, n = i0 & i1 & i2 & i3;
        o |= o >> 1;
        n &= n >> 1;
        const int cr = (y + 1) + kN * (z + 1);
        valid_rows[cr] = v;
        mixed_rows[cr] = v & o & ~n;
        if (y >= 0 && z >= 0) mixed_cells += std::popcount((mixed_rows[cr] >> kH) & 0xffu);
      }
  }
  // Cell (x, y, z) with all 8 corners active, for any cell in [-1, 9)^3.
  bool cell_valid(int x, int y, int z) const {
    const int r = row(y, z);
    constexpr int D = CellTile::kDim;
    const std::uint32_t a = active_rows[r] & active_rows[r + 1] & active_rows[r + D] & active_rows[r + D + 1];
    return ((a >> (x + kH)) & 3u) == 3u;
  }
  std::uint32_t mixed_row(int y, int z) const { return mixed_rows[(y + 1) + kN * (z + 1)]; }
  // Grid edges from (x, y, z), x in [-1, 9), along axis a whose both ends are active and lie on
  // opposite sides of iso: bit x + 1 of c[a]. Rows y, z in [-1, 9].
  void crossing_edges(int y, int z, std::uint32_t c[3]) const {
    const int r = row(y, z);
    const std::uint32_t act = active_rows[r], ins = inside_rows[r];
    const int nb[3] = {0, r + 1, r + CellTile::kDim};
    c[0] = act & (act >> 1) & (ins ^ (ins >> 1));
    for (int a = 1; a < 3; ++a) c[a] = act & active_rows[nb[a]] & (ins ^ inside_rows[nb[a]]);
    for (int a = 0; a < 3; ++a) c[a] = (c[a] >> (kH - 1)) & 0x3ffu;
  }
  // The grid edges from (x, y, z), x in [0, 8), y, z in [0, 8), that cross iso and belong to
  // a contoured cell (crossing_edges and edge_used), as 24 bits: bit 3 x + a (slot order).
  std::uint32_t owned_edges(int y, int z) const {
    std::uint32_t c[3];
    crossing_edges(y, z, c);
    auto vr = [&](int yy, int zz) { return valid_rows[std::size_t((yy + 1) + kN * (zz + 1))]; };
    const std::uint32_t v = vr(y, z), vy = vr(y - 1, z), vz = vr(y, z - 1), vyz = vr(y - 1, z - 1);
    const std::uint32_t m1 = v | vz, m2 = v | vy;
    const std::uint32_t used[3] = {v | vy | vz | vyz, m1 | (m1 << 1), m2 | (m2 << 1)};  // bit x + kH
    std::uint32_t out = 0;
    for (int a = 0; a < 3; ++a) out |= spread3((((c[a] & used[a]) >> kH) & 0xffu)) << a;
    return out;
  }
  // Bit x of m (8 bits) moved to bit 3 x (a table: the bit loop was ~3 % of marching cubes).
  static std::uint32_t spread3(std::uint32_t m) { return kSpread3[m & 0xffu]; }
  static constexpr std::array<std::uint32_t, 256> kSpread3 = [] {
    std::array<std::uint32_t, 256> t{};
    for (std::uint32_t m = 0; m < 256; ++m)
      for (int x = 0; x < 8; ++x) t[m] |= ((m >> x) & 1u) << (3 * x);
    return t;
  }();
  // Bits of crossing_edges for x in [lo, hi).
  static constexpr std::uint32_t x_bits(int lo, int hi) { return ((1u << (hi + 1)) - 1u) & ~((1u << (lo + 1)) - 1u); }
  // Any of the 4 cells around the edge from (x,y,z) along axis a is valid.
  bool edge_used(int x, int y, int z, int a) const {
    const int b = a == 0 ? 1 : 0, c = a == 2 ? 1 : 2;
    for (int ob = 0; ob < 2; ++ob)
      for (int oc = 0; oc < 2; ++oc) {
        int p[3] = {x, y, z};
        p[b] -= ob;
        p[c] -= oc;
        if (at(p[0], p[1], p[2])) return true;
      }
    return false;
  }
};

// Edge crossings of one tile: the parameter s in [0, 1] of the iso crossing on the edge from
// tile voxel p along axis a, computed once per edge (one division) for every crossing edge
// whose lower end lies in [lo, 9)^3. Other entries are stale.
struct EdgeCrossings {
  std::vector<double> s = std::vector<double>(3 * CellTile::kSize);
  void compute(const CellTile& t, const ValidCells& v, double iso, int lo) {
    compute(t, v, iso, lo, [](int, int, int, int, int) {});
  }
  // The same, calling also(x, y, z, a, p) for each crossing edge (p: tile index of (x, y, z)).
  template <typename Also>
  void compute(const CellTile& t, const ValidCells& v, double iso, int lo, Also&& also) {
    for (int z = lo; z <= kBrickDim; ++z)
      for (int y = lo; y <= kBrickDim; ++y) {
        std::uint32_t cr[3];
        v.crossing_edges(y, z, cr);
        for (std::uint32_t bits = (cr[0] | cr[1] | cr[2]) & ValidCells::x_bits(lo, kBrickDim + 1); bits != 0;
             bits &= bits - 1) {
          const int x = std::countr_zero(bits) - 1;
          const int p = CellTile::index(x, y, z);
          for (int a = 0; a < 3; ++a) {
            if (!((cr[a] >> (x + 1)) & 1u)) continue;
            const double ap = double(t.values[p]) - iso, aq = double(t.values[p + kTileStride[a]]) - iso;
            s[std::size_t(3 * p + a)] = ap / (ap - aq);
            also(x, y, z, a, p);
          }
        }
      }
  }
  double at(int p, int a) const { return s[std::size_t(3 * p + a)]; }
  // Tile-local point of the crossing on the edge from (x, y, z) along a.
  Vec3d point(int x, int y, int z, int a) const {
    const double s = at(CellTile::index(x, y, z), a);
    return {double(x) + (a == 0 ? s : 0.0), double(y) + (a == 1 ? s : 0.0), double(z) + (a == 2 ? s : 0.0)};
  }
};

// A bitmap over the slots of one brick with rank (set bits below a slot) in O(1).
template <int Slots>
struct SlotBits {
  static constexpr int kWords = (Slots + 63) / 64;
  std::array<std::uint64_t, kWords> words{};
  std::array<std::uint32_t, kWords> base{};
  void set(int s) { words[s >> 6] |= std::uint64_t{1} << (s & 63); }
  // Sets the slots [s, s + 32) where bits has a bit (bit i: slot s + i).
  void set_bits(int s, std::uint32_t bits) {
    const int w = s >> 6, o = s & 63;
    words[w] |= std::uint64_t{bits} << o;
    if (o > 32 && w + 1 < kWords) words[w + 1] |= std::uint64_t{bits} >> (64 - o);
  }
  bool test(int s) const { return (words[s >> 6] >> (s & 63)) & 1u; }
  void finish() {
    std::uint32_t acc = 0;
    for (int w = 0; w < kWords; ++w) {
      base[w] = acc;
      acc += std::uint32_t(std::popcount(words[w]));
    }
  }
  std::uint32_t rank(int s) const {
    return base[s >> 6] + std::uint32_t(std::popcount(words[s >> 6] & ((std::uint64_t{1} << (s & 63)) - 1)));
  }
};

inline Vec3f normalized_f(const Vec3d& g) {
  const double l = length(g);
  if (!(l > 0.0)) return {0.0f, 0.0f, 0.0f};
  return {float(g.x / l), float(g.y / l), float(g.z / l)};
}

// Central-difference gradient at tile voxel p (value units per voxel).
inline Vec3d corner_gradient(const CellTile& t, int p) {
  const float* v = t.values.data();
  return {0.5 * (double(v[p + kTileStride[0]]) - double(v[p - kTileStride[0]])),
          0.5 * (double(v[p + kTileStride[1]]) - double(v[p - kTileStride[1]])),
          0.5 * (double(v[p + kTileStride[2]]) - double(v[p - kTileStride[2]]))};
}

// Level set gradient at local point c inside cell (x,y,z): trilinear blend of the corner
// central differences.
inline Vec3d gradient_at(const CellTile& t, const Vec3d& c, int x, int y, int z) {
  const double fx = c.x - x, fy = c.y - y, fz = c.z - z;
  const int p0 = CellTile::index(x, y, z);
  Vec3d g{};
  for (int i = 0; i < 8; ++i) {
    const double w = ((i & 1) ? fx : 1 - fx) * ((i & 2) ? fy : 1 - fy) * ((i & 4) ? fz : 1 - fz);
    g += corner_gradient(t, p0 + kCornerOffset[i]) * w;
  }
  return g;
}

// Cosine of the smallest angle of a triangle with squared side lengths a2 <= ... (any order):
// the smallest angle faces the shortest side (law of cosines). 1 when degenerate.
inline double max_cos_from_squares(double a2, double b2, double c2) {
  if (b2 < a2) std::swap(a2, b2);
  if (c2 < a2) std::swap(a2, c2);
  const double bc = b2 * c2;
  if (!(a2 > 0.0 && bc > 0.0)) return 1.0;
  return (b2 + c2 - a2) / (2.0 * std::sqrt(bc));
}

// Quad p0 p1 p2 p3: true when the diagonal p0-p2 is the Delaunay one (the angles at p1 and p3
// facing it sum to at most pi: cot a1 + cot a3 >= 0), which for a planar convex quad is the
// split that maximises the smallest angle. Two square roots, no division.
// Both square roots in one instruction where SSE2 has it (the same correctly rounded values;
// the scalar form waited on one, then the other: the quads' split was ~5 % of marching cubes).
inline bool split_02(const Vec3d* p) {
  const Vec3d u1 = p[0] - p[1], v1 = p[2] - p[1], u3 = p[0] - p[3], v3 = p[2] - p[3];
  const Vec3d c1 = cross(u1, v1), c3 = cross(u3, v3);
#if defined(__SSE2__)
  alignas(16) double s[2];
  _mm_store_pd(s, _mm_sqrt_pd(_mm_set_pd(dot(c3, c3), dot(c1, c1))));
  const double s1 = s[0], s3 = s[1];
#else
  const double s1 = std::sqrt(dot(c1, c1)), s3 = std::sqrt(dot(c3, c3));
#endif
  return dot(u1, v1) * s3 + dot(u3, v3) * s1 >= 0.0;
}

// Fan apex for a polygon of n in [4, 12] vertices that maximises the smallest angle (quads:
// the Delaunay diagonal, fan from 0 or 1). First apex wins ties. surface/fan_choice.cpp.
int best_fan_start(const Vec3d* p, int n);

// Per-thread storage for the bricks' outputs until the merge: a brick's arrays, built in
// reused scratch vectors, are copied into the thread's chunks (kChunkBytes each, huge pages
// advised), so no brick allocates, and fresh memory is faulted in 2 MiB at a time (the
// per-brick vectors were ~5 % of a warm extraction in malloc / free, and most of what a first
// extraction in a fresh process pays more than a later one). Items keep their alignment.
// Threading: one arena per thread. Not copyable; spans stay valid until it is destroyed.
class OutputArena {
 public:
  static constexpr std::size_t kChunkBytes = std::size_t{4} << 20;
  OutputArena() = default;
  OutputArena(const OutputArena&) = delete;
  OutputArena& operator=(const OutputArena&) = delete;
  ~OutputArena() {
    for (std::byte* c : chunks_) ::operator delete[](c, std::align_val_t(kAlign));
  }
  template <typename T>
  std::span<const T> keep(const std::vector<T>& items) {
    if (items.empty()) return {};
    const std::size_t bytes = items.size() * sizeof(T);
    std::byte* at = allocate(bytes, alignof(T));
    std::memcpy(at, items.data(), bytes);
    return {reinterpret_cast<const T*>(at), items.size()};
  }

 private:
  static constexpr std::size_t kAlign = std::size_t{2} << 20;
  std::byte* allocate(std::size_t bytes, std::size_t align) {
    used_ = (used_ + align - 1) & ~(align - 1);
    if (chunks_.empty() || used_ + bytes > size_) {
      size_ = std::max(kChunkBytes, (bytes + kAlign - 1) & ~(kAlign - 1));
      chunks_.push_back(static_cast<std::byte*>(::operator new[](size_, std::align_val_t(kAlign))));
      prefault_for_write(chunks_.back(), size_);
      used_ = 0;
    }
    std::byte* at = chunks_.back() + used_;
    used_ += bytes;
    return at;
  }
  std::vector<std::byte*> chunks_;
  std::size_t size_ = 0, used_ = 0;
};

void check_iso(const NarrowBand& band, double iso, std::string_view where);

// The start both extractors share for one brick: gathers its tile, records the neighbourhood
// the output's vertex keys refer to, classifies the tile's rows, reserves the vertex buffers;
// returns the world position of the brick's voxel (0, 0, 0).
template <typename Out>
Vec3d begin_brick(const NarrowBand& band, std::uint32_t b, double iso, CellTile& t, ValidCells& valid, Out& out,
                  std::span<const float> decoded = {}) {
  gather_cell_tile(band, b, t, decoded);
  out.around = t.around;
  valid.compute(t, iso);
  out.vertices.reserve(std::size_t(valid.mixed_cells) + 8);
  out.normals.reserve(std::size_t(valid.mixed_cells) + 8);
  const Coord base = brick_origin(band.bricks()[b].coord);
  return band.origin() + Vec3d{double(base.x), double(base.y), double(base.z)} * band.voxel_size();
}

// Which bricks can own output at iso: a brick owns the cells and grid edges whose lowest voxel
// lies in it, so it has work only when the active values of itself and its 7 upper neighbours
// (+x, +y, +z and their combinations) lie on both sides of iso. One pass over the values.
std::vector<std::uint8_t> bricks_with_crossings(const NarrowBand& band, double iso);
// The same from each brick's sides (bit 0: an active value below iso, bit 1: one not below).
std::vector<std::uint8_t> bricks_with_crossings(const NarrowBand& band, std::span<const std::uint8_t> sides);

// f(brick) for every brick: TBB inside batches, progress.step between batches (serial), the
// fraction running from `from` to `to` (a pass of a multi-pass operation reports its share).
void for_brick_batches(std::uint32_t bricks, const ProgressHook& progress, std::string_view stage,
                       const std::function<void(std::uint32_t)>& f, double from = 0.0, double to = 1.0);

// Sizes the result's vertex, normal and triangle arrays (empty before) side by side: sizing
// zero-fills tens of MB, after their pages are faulted in by one call each
// (resize_with_huge_pages).
void size_result(SurfaceResult& r, std::size_t vertices, std::size_t triangles);

// Vertex keys of the per-brick outputs: the owning brick as its slot in the emitting brick's
// 3x3x3 neighbourhood (Neighborhood::slot, 5 bits) and the vertex slot in that brick.
inline constexpr int kKeySlotBits = 13;
using VertexKey = std::uint32_t;
inline VertexKey vertex_key(int neighbor_slot, int slot) {
  return VertexKey(neighbor_slot) << kKeySlotBits | VertexKey(slot);
}
inline int key_neighbor(VertexKey k) { return int(k >> kKeySlotBits); }
inline int key_slot(VertexKey k) { return int(k & ((1u << kKeySlotBits) - 1)); }

// Concatenation of per-brick outputs in brick order, shared by both extractors. Out needs
// `vertices`, `normals`, `triangles` (3 VertexKeys each), `around` (the neighbourhood the keys
// refer to), `owned` (finish()) and `cells`. merge_offsets sizes the result and returns each
// brick's first vertex and triangle; copy_merged fills it in parallel, mapping keys to global
// indices with remap(owner brick, slot).
struct MergeOffsets {
  std::vector<std::uint32_t> vertex;    // first vertex of each brick (bricks + 1 entries)
  std::vector<std::uint64_t> triangle;  // first triangle of each brick (bricks + 1 entries)
};

// Quads (4 VertexKeys, outward order) of an Out that has them; split into 2 triangles at merge
// time, once every vertex position is known.
template <typename Out>
std::size_t quad_count(const Out& o) {
  if constexpr (requires { o.quads; }) return o.quads.size();
  else return 0;
}

template <typename Out>
MergeOffsets merge_offsets(std::vector<Out>& outs, SurfaceResult& r, std::string_view who) {
  const std::size_t nb = outs.size();
  MergeOffsets m{std::vector<std::uint32_t>(nb + 1, 0), std::vector<std::uint64_t>(nb + 1, 0)};
  std::uint64_t total = 0;
  for (std::size_t b = 0; b < nb; ++b) {
    m.vertex[b] = std::uint32_t(total);
    total += outs[b].vertices.size();
    if (total >= 0xffffffffull)
      throw Error(ErrorCode::LimitExceeded, std::string(who), "more than 2^32 - 1 vertices");
    m.triangle[b + 1] = m.triangle[b] + outs[b].triangles.size() + 2 * quad_count(outs[b]);
    outs[b].owned.finish();
    r.cells_with_surface += outs[b].cells;
  }
  m.vertex[nb] = std::uint32_t(total);
  size_result(r, total, m.triangle[nb]);
  return m;
}

// Two parallel passes over the bricks: vertices and normals, then triangles (quads are split
// along their Delaunay diagonal, which needs the vertices of neighbouring bricks).
template <typename Out, typename Remap>
void copy_merged(const std::vector<Out>& outs, const MergeOffsets& m, Remap&& remap, SurfaceResult& r) {
  const tbb::blocked_range<std::size_t> all(0, outs.size(), 64);
  tbb::parallel_for(all, [&](const tbb::blocked_range<std::size_t>& rg) {
    for (std::size_t b = rg.begin(); b != rg.end(); ++b) {
      std::copy(outs[b].vertices.begin(), outs[b].vertices.end(), r.mesh.vertices.begin() + m.vertex[b]);
      std::copy(outs[b].normals.begin(), outs[b].normals.end(), r.normals.begin() + m.vertex[b]);
    }
  });
  tbb::parallel_for(all, [&](const tbb::blocked_range<std::size_t>& rg) {
    for (std::size_t b = rg.begin(); b != rg.end(); ++b) {
      const Out& o = outs[b];
      auto global = [&](VertexKey key) { return remap(o.around[std::size_t(key_neighbor(key))], key_slot(key)); };
      auto* dst = r.mesh.triangles.data() + m.triangle[b];
      for (const auto& k : o.triangles) *dst++ = {global(k[0]), global(k[1]), global(k[2])};
      if constexpr (requires { o.quads; }) {
        for (const auto& k : o.quads) {
          const std::uint32_t g[4] = {global(k[0]), global(k[1]), global(k[2]), global(k[3])};
          const Vec3d p[4] = {r.mesh.vertices[g[0]], r.mesh.vertices[g[1]], r.mesh.vertices[g[2]], r.mesh.vertices[g[3]]};
          if (split_02(p)) {
            *dst++ = {g[0], g[1], g[2]};
            *dst++ = {g[0], g[2], g[3]};
          } else {
            *dst++ = {g[1], g[2], g[3]};
            *dst++ = {g[1], g[3], g[0]};
          }
        }
      }
    }
  });
}

}  // namespace levelset::surface_detail
