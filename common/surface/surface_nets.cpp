#include "surface/surface_nets.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <chrono>
#include <cmath>

#include <tbb/enumerable_thread_specific.h>

#include "core/error.hpp"
#include "surface/cell_loops.hpp"
#include "surface/cell_tile.hpp"
#include "surface/surface_common.hpp"

namespace levelset {

using namespace surface_detail;

namespace {

constexpr int kLoopSlots = kBrickVoxels * 4;  // 2048
constexpr int kSlotBits = 12;

struct BrickOut {
  std::vector<Vec3d> vertices;
  std::vector<Vec3f> normals;
  std::vector<std::array<std::uint64_t, 3>> triangles;  // owner << 12 | slot
  SlotBits<kLoopSlots> owned;
  std::uint64_t cells = 0;
};

const cell::LoopSet& cell_loops(const CellTile& t, int x, int y, int z, double iso) {
  double a[8];
  const int p0 = CellTile::index(x, y, z);
  for (int i = 0; i < 8; ++i) a[i] = double(t.values[p0 + kCornerOffset[i]]) - iso;
  int m, d;
  cell::classify(a, m, d);
  return cell::loops_for(m, d);
}

// The 8 corner values (minus iso) and corner central differences of one cell, gathered once
// and reused by every Newton step and the normal (same arithmetic as gradient_at/trilinear).
struct CellCorners {
  double a[8];
  Vec3d g[8];
  CellCorners(const CellTile& t, int x, int y, int z, double iso) {
    const int p0 = CellTile::index(x, y, z);
    for (int i = 0; i < 8; ++i) {
      a[i] = double(t.values[p0 + kCornerOffset[i]]) - iso;
      g[i] = corner_gradient(t, p0 + kCornerOffset[i]);
    }
  }
  void eval(const Vec3d& c, int x, int y, int z, double& phi, Vec3d& grad) const {
    const double fx = c.x - x, fy = c.y - y, fz = c.z - z;
    double v = 0.0;
    Vec3d gg{};
    for (int i = 0; i < 8; ++i) {
      const double w = ((i & 1) ? fx : 1 - fx) * ((i & 2) ? fy : 1 - fy) * ((i & 4) ? fz : 1 - fz);
      v += a[i] * w;
      gg += g[i] * w;
    }
    phi = v;
    grad = gg;
  }
  Vec3d gradient(const Vec3d& c, int x, int y, int z) const {
    const double fx = c.x - x, fy = c.y - y, fz = c.z - z;
    Vec3d gg{};
    for (int i = 0; i < 8; ++i) {
      const double w = ((i & 1) ? fx : 1 - fx) * ((i & 2) ? fy : 1 - fy) * ((i & 4) ? fz : 1 - fz);
      gg += g[i] * w;
    }
    return gg;
  }
};

// Local position of the vertex of loop l of cell (x,y,z).
Vec3d loop_vertex(const CellTile& t, const CellCorners& cc, int x, int y, int z, const cell::LoopSet& ls,
                  int l, double iso, int iterations) {
  Vec3d c{};
  const int n = ls.length[l];
  for (int i = 0; i < n; ++i) {
    const int e = ls.edges[ls.begin[l] + i];
    const int k = cell::edge_lower_corner(e);
    c += edge_point_position(t, x + (k & 1), y + ((k >> 1) & 1), z + ((k >> 2) & 1), e >> 2, iso);
  }
  c = c / double(n);
  for (int it = 0; it < iterations; ++it) {
    double phi;
    Vec3d g;
    cc.eval(c, x, y, z, phi, g);
    const double gg = dot(g, g);
    if (!(gg > 1e-12)) break;
    c -= g * (phi / gg);
    c = {std::clamp(c.x, double(x), double(x + 1)), std::clamp(c.y, double(y), double(y + 1)),
         std::clamp(c.z, double(z), double(z + 1))};
  }
  return c;
}

// Per-thread scratch: the tile and the loop vertices of the cells with min corner in [-1, 8)^3,
// computed at most once per brick.
struct Scratch {
  CellTile tile;
  std::array<std::uint8_t, ValidCells::kN * ValidCells::kN * ValidCells::kN> done{};
  std::array<const cell::LoopSet*, ValidCells::kN * ValidCells::kN * ValidCells::kN> loops{};
  std::array<std::array<Vec3d, 4>, ValidCells::kN * ValidCells::kN * ValidCells::kN> verts{};
};

void process_brick(const NarrowBand& band, std::uint32_t b, double iso, int iterations,
                   Scratch& s, BrickOut& out) {
  CellTile& t = s.tile;
  gather_cell_tile(band, b, t);
  const Coord base = brick_origin(band.bricks()[b].coord);
  const Vec3d bw{double(base.x), double(base.y), double(base.z)};
  const double h = band.voxel_size();
  const Vec3d org = band.origin();
  ValidCells valid;
  valid.compute(t, iso);
  s.done.fill(0);

  // Loops and vertices of a valid cell (cached).
  auto cell_at = [&](int x, int y, int z) -> const cell::LoopSet& {
    const int ci = ValidCells::index(x, y, z);
    if (!s.done[ci]) {
      s.done[ci] = 1;
      const cell::LoopSet& ls = cell_loops(t, x, y, z, iso);
      s.loops[ci] = &ls;
      if (ls.loop_count != 0) {
        const CellCorners cc(t, x, y, z, iso);
        for (int l = 0; l < ls.loop_count; ++l) s.verts[ci][l] = loop_vertex(t, cc, x, y, z, ls, l, iso, iterations);
      }
    }
    return *s.loops[ci];
  };

  // Owned cell-loop vertices in slot order.
  for (int z = 0; z < kBrickDim; ++z)
    for (int y = 0; y < kBrickDim; ++y)
      for (std::uint32_t bits = (valid.mixed_row(y, z) >> ValidCells::kH) & 0xffu; bits != 0; bits &= bits - 1) {
        const int x = std::countr_zero(bits);
        const cell::LoopSet& ls = cell_at(x, y, z);
        if (ls.loop_count == 0) continue;
        ++out.cells;
        const CellCorners cc(t, x, y, z, iso);
        const int ci = ValidCells::index(x, y, z);
        for (int l = 0; l < ls.loop_count; ++l) {
          const Vec3d c = s.verts[ci][l];
          out.owned.set(4 * local_index(x, y, z) + l);
          out.vertices.push_back(org + (bw + c) * h);
          out.normals.push_back(normalized_f(cc.gradient(c, x, y, z)));
        }
      }

  // Quads around owned crossing edges.
  for (int z = 0; z < kBrickDim; ++z)
    for (int y = 0; y < kBrickDim; ++y) {
      std::uint32_t cr[3];
      valid.crossing_edges(y, z, cr);
      for (std::uint32_t bits = cr[0] | cr[1] | cr[2]; bits != 0; bits &= bits - 1) {
        const int x = std::countr_zero(bits);
        const int p = CellTile::index(x, y, z);
        const bool p_in = double(t.values[p]) - iso < 0.0;
        for (int a = 0; a < 3; ++a) {
          if (!((cr[a] >> x) & 1u)) continue;
          const int bax = a == 0 ? 1 : 0, cax = a == 2 ? 1 : 2;
          static constexpr int kOrder[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
          std::array<std::uint64_t, 4> key;
          std::array<Vec3d, 4> pos;
          bool ok = true;
          for (int k = 0; k < 4 && ok; ++k) {
            int c[3] = {x, y, z};
            c[bax] -= kOrder[k][0];
            c[cax] -= kOrder[k][1];
            if (!valid.at(c[0], c[1], c[2])) { ok = false; break; }
            const cell::LoopSet& ls = cell_at(c[0], c[1], c[2]);
            const int e = 4 * a + kOrder[k][0] + 2 * kOrder[k][1];
            const int l = ls.loop_of_edge[e];
            pos[k] = s.verts[ValidCells::index(c[0], c[1], c[2])][l];
            const int owner = CellTile::neighbor_slot(c[0] < 0 ? -1 : 0, c[1] < 0 ? -1 : 0, c[2] < 0 ? -1 : 0);
            key[k] = (std::uint64_t(t.around[owner]) << kSlotBits) |
                     std::uint64_t(4 * local_index(c[0] & 7, c[1] & 7, c[2] & 7) + l);
          }
          if (!ok) continue;
          // kOrder turns about +a for x and z and about -a for y; outside lies at +a when p is in.
          if ((a == 1) == p_in) {
            std::swap(key[1], key[3]);
            std::swap(pos[1], pos[3]);
          }
          const double d02 = std::max(max_cos(pos[0], pos[1], pos[2]), max_cos(pos[0], pos[2], pos[3]));
          const double d13 = std::max(max_cos(pos[1], pos[2], pos[3]), max_cos(pos[1], pos[3], pos[0]));
          if (d02 <= d13) {
            out.triangles.push_back({key[0], key[1], key[2]});
            out.triangles.push_back({key[0], key[2], key[3]});
          } else {
            out.triangles.push_back({key[1], key[2], key[3]});
            out.triangles.push_back({key[1], key[3], key[0]});
          }
        }
      }
    }
}

}  // namespace

SurfaceResult surface_nets(const NarrowBand& band, const SurfaceNetsOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  check_iso(band, options.iso, "surface_nets");
  if (options.relax_iterations < 0)
    throw Error(ErrorCode::InvalidArgument, "surface_nets", "relax_iterations must be >= 0");
  const std::uint32_t nb = std::uint32_t(band.brick_count());
  std::vector<BrickOut> outs(nb);
  tbb::enumerable_thread_specific<Scratch> scratch;
  for_brick_batches(nb, options.progress, "surface_nets", [&](std::uint32_t b) {
    process_brick(band, b, options.iso, options.relax_iterations, scratch.local(), outs[b]);
  });
  SurfaceResult r;
  const MergeOffsets m = merge_offsets(outs, r, "surface_nets");
  auto remap = [&](std::uint64_t k) {
    const std::uint32_t owner = std::uint32_t(k >> kSlotBits);
    return m.vertex[owner] + outs[owner].owned.rank(int(k & ((1u << kSlotBits) - 1)));
  };
  copy_merged(outs, m, remap, r);
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return r;
}

}  // namespace levelset
