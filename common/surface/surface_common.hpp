// Internal helpers shared by marching_cubes and surface_nets: tile strides, valid cells,
// per-brick slot bitmaps with O(1) rank, edge crossings with gradient normals, the fan choice,
// option checks and the batched parallel brick loop. Units: tile-local index space (voxel
// units relative to the brick origin). Threading: plain functions over per-thread data.
#pragma once

#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "core/error.hpp"
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
  std::array<std::uint8_t, kN * kN * kN> flags{};
  static int index(int x, int y, int z) { return (x + 1) + kN * ((y + 1) + kN * (z + 1)); }
  bool at(int x, int y, int z) const { return flags[index(x, y, z)] != 0; }
  // Row bitmasks over x (bit x + kHalo) for every tile row (y, z): active and inside (< iso).
  static constexpr int kH = CellTile::kHalo;
  static int row(int y, int z) { return (y + kH) + CellTile::kDim * (z + kH); }
  std::array<std::uint32_t, CellTile::kDim * CellTile::kDim> active_rows{}, inside_rows{};
  // Per cell row (y, z) in [-1, 8)^2: valid cells and valid cells crossing iso (bit x + kHalo).
  std::array<std::uint32_t, kN * kN> valid_rows{}, mixed_rows{};
  void compute(const CellTile& t, double iso = 0.0) {
    for (int z = -kH; z < kBrickDim + kH; ++z)
      for (int y = -kH; y < kBrickDim + kH; ++y) {
        const int p = CellTile::index(-kH, y, z);
        std::uint32_t act = 0, ins = 0;
        for (int x = 0; x < CellTile::kDim; ++x) {
          act |= std::uint32_t(t.active[p + x] != 0) << x;
          ins |= std::uint32_t(double(t.values[p + x]) < iso) << x;
        }
        active_rows[row(y, z)] = act;
        inside_rows[row(y, z)] = ins;
      }
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
        for (int x = -1; x < kBrickDim; ++x) flags[index(x, y, z)] = std::uint8_t((v >> (x + kH)) & 1u);
      }
  }
  std::uint32_t mixed_row(int y, int z) const { return mixed_rows[(y + 1) + kN * (z + 1)]; }
  // Grid edges from (x, y, z), x in [0, 8), along axis a whose both ends are active and lie on
  // opposite sides of iso: bit x of c[a].
  void crossing_edges(int y, int z, std::uint32_t c[3]) const {
    const int r = row(y, z);
    const std::uint32_t act = active_rows[r], ins = inside_rows[r];
    const int nb[3] = {0, r + 1, r + CellTile::kDim};
    c[0] = act & (act >> 1) & (ins ^ (ins >> 1));
    for (int a = 1; a < 3; ++a) c[a] = act & active_rows[nb[a]] & (ins ^ inside_rows[nb[a]]);
    for (int a = 0; a < 3; ++a) c[a] = (c[a] >> kH) & 0xffu;
  }
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

// A bitmap over the slots of one brick with rank (set bits below a slot) in O(1).
template <int Slots>
struct SlotBits {
  static constexpr int kWords = (Slots + 63) / 64;
  std::array<std::uint64_t, kWords> words{};
  std::array<std::uint32_t, kWords> base{};
  void set(int s) { words[s >> 6] |= std::uint64_t{1} << (s & 63); }
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

inline Vec3d corner_gradient(const CellTile& t, int p) {
  const float* v = t.values.data();
  return {0.5 * (double(v[p + kTileStride[0]]) - double(v[p - kTileStride[0]])),
          0.5 * (double(v[p + kTileStride[1]]) - double(v[p - kTileStride[1]])),
          0.5 * (double(v[p + kTileStride[2]]) - double(v[p - kTileStride[2]]))};
}

inline Vec3f normalized_f(const Vec3d& g) {
  const double l = length(g);
  if (!(l > 0.0)) return {0.0f, 0.0f, 0.0f};
  return {float(g.x / l), float(g.y / l), float(g.z / l)};
}

inline double edge_parameter(const CellTile& t, int p, int q, double iso) {
  const double ap = double(t.values[p]) - iso, aq = double(t.values[q]) - iso;
  return ap / (ap - aq);
}

inline Vec3d edge_point_position(const CellTile& t, int x, int y, int z, int a, double iso) {
  const int p = CellTile::index(x, y, z);
  const double s = edge_parameter(t, p, p + kTileStride[a], iso);
  Vec3d r{double(x), double(y), double(z)};
  r[a] += s;
  return r;
}

struct EdgePoint {
  Vec3d local;
  Vec3f normal;
};

inline EdgePoint edge_point(const CellTile& t, int x, int y, int z, int a, double iso) {
  const int p = CellTile::index(x, y, z), q = p + kTileStride[a];
  const double s = edge_parameter(t, p, q, iso);
  EdgePoint e;
  e.local = {double(x), double(y), double(z)};
  e.local[a] += s;
  e.normal = normalized_f(corner_gradient(t, p) * (1.0 - s) + corner_gradient(t, q) * s);
  return e;
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

// Largest cosine of the three angles of a triangle (1 when degenerate).
inline double max_cos(const Vec3d& a, const Vec3d& b, const Vec3d& c) {
  const Vec3d ab = b - a, bc = c - b, ca = a - c;
  const double lab = length(ab), lbc = length(bc), lca = length(ca);
  if (!(lab > 0 && lbc > 0 && lca > 0)) return 1.0;
  const double c1 = -dot(ab, ca) / (lab * lca), c2 = -dot(ab, bc) / (lab * lbc),
               c3 = -dot(bc, ca) / (lbc * lca);
  return std::max(c1, std::max(c2, c3));
}

// Fan apex for a polygon of n >= 4 vertices that maximises the smallest angle.
inline int best_fan_start(const Vec3d* p, int n) {
  if (n == 4) {
    // Fans at 2 and 3 repeat the triangles of fans 0 and 1 (max_cos is invariant under cyclic
    // rotation), and ties keep the earliest start: same answer as the general loop.
    const double w0 = std::max(max_cos(p[0], p[1], p[2]), max_cos(p[0], p[2], p[3]));
    const double w1 = std::max(max_cos(p[1], p[2], p[3]), max_cos(p[1], p[3], p[0]));
    return w1 < w0 ? 1 : 0;
  }
  int best = 0;
  double best_cos = 2.0;
  for (int s = 0; s < n; ++s) {
    double worst = -2.0;
    for (int i = 1; i + 1 < n; ++i)
      worst = std::max(worst, max_cos(p[s], p[(s + i) % n], p[(s + i + 1) % n]));
    if (worst < best_cos) {
      best_cos = worst;
      best = s;
    }
  }
  return best;
}

void check_iso(const NarrowBand& band, double iso, std::string_view where);

// f(brick) for every brick: TBB inside batches, progress.step between batches (serial).
void for_brick_batches(std::uint32_t bricks, const ProgressHook& progress, std::string_view stage,
                       const std::function<void(std::uint32_t)>& f);

// Concatenation of per-brick outputs in brick order, shared by both extractors. Out needs
// `vertices`, `normals`, `triangles` (3 brick-local keys each), `owned` (finish()) and `cells`.
// merge_offsets sizes the result and returns each brick's first vertex and triangle;
// copy_merged fills it in parallel, mapping keys to global indices with remap(key).
struct MergeOffsets {
  std::vector<std::uint32_t> vertex;    // first vertex of each brick (bricks + 1 entries)
  std::vector<std::uint64_t> triangle;  // first triangle of each brick (bricks + 1 entries)
};

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
    m.triangle[b + 1] = m.triangle[b] + outs[b].triangles.size();
    outs[b].owned.finish();
    r.cells_with_surface += outs[b].cells;
  }
  m.vertex[nb] = std::uint32_t(total);
  r.mesh.vertices.resize(total);
  r.normals.resize(total);
  r.mesh.triangles.resize(m.triangle[nb]);
  return m;
}

template <typename Out, typename Remap>
void copy_merged(const std::vector<Out>& outs, const MergeOffsets& m, Remap&& remap, SurfaceResult& r) {
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, outs.size(), 64),
                    [&](const tbb::blocked_range<std::size_t>& rg) {
    for (std::size_t b = rg.begin(); b != rg.end(); ++b) {
      const Out& o = outs[b];
      std::copy(o.vertices.begin(), o.vertices.end(), r.mesh.vertices.begin() + m.vertex[b]);
      std::copy(o.normals.begin(), o.normals.end(), r.normals.begin() + m.vertex[b]);
      for (std::size_t i = 0; i < o.triangles.size(); ++i) {
        const auto& k = o.triangles[i];
        r.mesh.triangles[m.triangle[b] + i] = {remap(k[0]), remap(k[1]), remap(k[2])};
      }
    }
  });
}

}  // namespace levelset::surface_detail
