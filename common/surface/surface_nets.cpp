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

struct BrickOut {
  std::vector<Vec3d> vertices;
  std::vector<Vec3f> normals;
  std::vector<std::array<VertexKey, 3>> triangles;
  std::array<std::uint32_t, 27> around{};
  SlotBits<kLoopSlots> owned;
  std::uint64_t cells = 0;
};

// One cell's corner values (minus iso) and corner central differences as 4 channels
// (phi, gx, gy, gz), trilinearly interpolated at a local point f in [0, 1]^3.
struct CellField {
  double v[8][4];
  CellField(const CellTile& t, const GradientTile& gt, int p0, double iso) {
    for (int i = 0; i < 8; ++i) {
      const std::size_t p = std::size_t(p0 + kCornerOffset[i]);
      v[i][0] = double(t.values[p]) - iso;
      for (int a = 0; a < 3; ++a) v[i][a + 1] = double(gt.g[a][p]);
    }
  }
  void eval(const Vec3d& f, double out[4]) const {
    double r[4][4], q[2][4];
    for (int k = 0; k < 4; ++k)
      for (int c = 0; c < 4; ++c) r[k][c] = v[2 * k][c] + f.x * (v[2 * k + 1][c] - v[2 * k][c]);
    for (int j = 0; j < 2; ++j)
      for (int c = 0; c < 4; ++c) q[j][c] = r[2 * j][c] + f.y * (r[2 * j + 1][c] - r[2 * j][c]);
    for (int c = 0; c < 4; ++c) out[c] = q[0][c] + f.z * (q[1][c] - q[0][c]);
  }
};

// Vertex of loop l of a cell in cell-local coordinates [0, 1]^3: the mean of its edge
// crossings, then Newton steps along the interpolated gradient onto the trilinear zero level
// (stopping once a step would move it by less than 1e-7 voxel).
Vec3d loop_vertex(const EdgeCrossings& edges, const CellField& cf, int x, int y, int z,
                  const cell::LoopSet& ls, int l, int iterations) {
  Vec3d c{};
  const int n = ls.length[l];
  for (int i = 0; i < n; ++i) {
    const int e = ls.edges[ls.begin[l] + i];
    const int k = cell::edge_lower_corner(e);
    c += edges.point(x + (k & 1), y + ((k >> 1) & 1), z + ((k >> 2) & 1), e >> 2);
  }
  c = c / double(n) - Vec3d{double(x), double(y), double(z)};
  for (int it = 0; it < iterations; ++it) {
    double f[4];
    cf.eval(c, f);
    const double gg = f[1] * f[1] + f[2] * f[2] + f[3] * f[3];
    if (!(gg > 1e-12) || f[0] * f[0] < 1e-14 * gg) break;
    const double k = f[0] / gg;
    c = {std::clamp(c.x - k * f[1], 0.0, 1.0), std::clamp(c.y - k * f[2], 0.0, 1.0),
         std::clamp(c.z - k * f[3], 0.0, 1.0)};
  }
  return c;
}

constexpr int kCells = ValidCells::kN * ValidCells::kN * ValidCells::kN;

// Per-thread scratch: the tile and the loops and vertices (cell-local) of the cells with min
// corner in [-1, 8)^3 that cross iso.
struct Scratch {
  CellTile tile;
  EdgeCrossings edges;
  GradientTile grad;
  std::array<const cell::LoopSet*, kCells> loops{};
  std::array<std::array<Vec3d, 4>, kCells> verts{};
};

void process_brick(const NarrowBand& band, std::uint32_t b, double iso, int iterations,
                   Scratch& s, BrickOut& out) {
  CellTile& t = s.tile;
  gather_cell_tile(band, b, t);
  out.around = t.around;
  const Coord base = brick_origin(band.bricks()[b].coord);
  const double h = band.voxel_size();
  const Vec3d corner = band.origin() + Vec3d{double(base.x), double(base.y), double(base.z)} * h;
  ValidCells valid;
  valid.compute(t, iso);
  out.vertices.reserve(valid.mixed_cells + 8);
  out.normals.reserve(valid.mixed_cells + 8);
  out.triangles.reserve(2 * valid.mixed_cells + 8);
  s.edges.compute(t, valid, iso, -1);
  s.grad.compute(t, valid, -1);

  // Loops and vertices of every valid cell crossing iso; the owned ones (min corner in
  // [0, 8)^3) are emitted in slot order with their normals.
  for (int z = -1; z < kBrickDim; ++z)
    for (int y = -1; y < kBrickDim; ++y)
      for (std::uint32_t bits = valid.mixed_row(y, z) >> (ValidCells::kH - 1); bits != 0; bits &= bits - 1) {
        const int x = std::countr_zero(bits) - 1;
        const int p0 = CellTile::index(x, y, z);
        double a[8];
        for (int i = 0; i < 8; ++i) a[i] = double(t.values[p0 + kCornerOffset[i]]) - iso;
        int m, d;
        cell::classify(a, m, d);
        const cell::LoopSet& ls = cell::loops_for(m, d);
        const int ci = ValidCells::index(x, y, z);
        s.loops[ci] = &ls;
        if (ls.loop_count == 0) continue;
        const CellField cf(t, s.grad, p0, iso);
        const bool owned = x >= 0 && y >= 0 && z >= 0;
        out.cells += owned ? 1 : 0;
        for (int l = 0; l < ls.loop_count; ++l) {
          const Vec3d c = loop_vertex(s.edges, cf, x, y, z, ls, l, iterations);
          s.verts[ci][l] = c;
          if (!owned) continue;
          double f[4];
          cf.eval(c, f);
          out.owned.set(4 * local_index(x, y, z) + l);
          out.vertices.push_back(corner + (Vec3d{double(x), double(y), double(z)} + c) * h);
          out.normals.push_back(normalized_f({f[1], f[2], f[3]}));
        }
      }

  // Quads around owned crossing edges.
  for (int z = 0; z < kBrickDim; ++z)
    for (int y = 0; y < kBrickDim; ++y) {
      std::uint32_t cr[3];
      valid.crossing_edges(y, z, cr);
      for (std::uint32_t& c : cr) c = (c & ValidCells::x_bits(0, kBrickDim)) >> 1;  // owned edges, bit x
      for (std::uint32_t bits = cr[0] | cr[1] | cr[2]; bits != 0; bits &= bits - 1) {
        const int x = std::countr_zero(bits);
        const int p = CellTile::index(x, y, z);
        const bool p_in = double(t.values[p]) - iso < 0.0;
        for (int a = 0; a < 3; ++a) {
          if (!((cr[a] >> x) & 1u)) continue;
          const int bax = a == 0 ? 1 : 0, cax = a == 2 ? 1 : 2;
          static constexpr int kOrder[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
          std::array<VertexKey, 4> key;
          std::array<Vec3d, 4> pos;
          bool ok = true;
          for (int k = 0; k < 4 && ok; ++k) {
            int c[3] = {x, y, z};
            c[bax] -= kOrder[k][0];
            c[cax] -= kOrder[k][1];
            if (!valid.at(c[0], c[1], c[2])) { ok = false; break; }
            const int ci = ValidCells::index(c[0], c[1], c[2]);
            const int e = 4 * a + kOrder[k][0] + 2 * kOrder[k][1];
            const int l = s.loops[ci]->loop_of_edge[e];
            pos[k] = Vec3d{double(c[0]), double(c[1]), double(c[2])} + s.verts[ci][l];
            const int owner = CellTile::neighbor_slot(c[0] < 0 ? -1 : 0, c[1] < 0 ? -1 : 0, c[2] < 0 ? -1 : 0);
            key[k] = vertex_key(owner, 4 * local_index(c[0] & 7, c[1] & 7, c[2] & 7) + l);
          }
          if (!ok) continue;
          // kOrder turns about +a for x and z and about -a for y; outside lies at +a when p is in.
          if ((a == 1) == p_in) {
            std::swap(key[1], key[3]);
            std::swap(pos[1], pos[3]);
          }
          if (split_02(pos.data())) {
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
  const std::vector<std::uint8_t> work = bricks_with_crossings(band, options.iso);
  tbb::enumerable_thread_specific<Scratch> scratch;
  for_brick_batches(nb, options.progress, "surface_nets", [&](std::uint32_t b) {
    if (work[b]) process_brick(band, b, options.iso, options.relax_iterations, scratch.local(), outs[b]);
  });
  SurfaceResult r;
  const MergeOffsets m = merge_offsets(outs, r, "surface_nets");
  auto remap = [&](std::uint32_t owner, int slot) { return m.vertex[owner] + outs[owner].owned.rank(slot); };
  copy_merged(outs, m, remap, r);
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return r;
}

}  // namespace levelset
