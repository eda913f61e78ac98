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
#include <string_view>

#include "core/progress.hpp"
#include "core/vec3.hpp"
#include "grid/narrow_band.hpp"
#include "surface/cell_tile.hpp"

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
  void compute(const CellTile& t) {
    for (int z = -1; z < kBrickDim; ++z)
      for (int y = -1; y < kBrickDim; ++y)
        for (int x = -1; x < kBrickDim; ++x) {
          const int p = CellTile::index(x, y, z);
          std::uint8_t all = 1;
          for (int i = 0; i < 8; ++i) all &= t.active[p + kCornerOffset[i]];
          flags[index(x, y, z)] = all;
        }
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

}  // namespace levelset::surface_detail
