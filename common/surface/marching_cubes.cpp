#include "surface/marching_cubes.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <chrono>
#include <cmath>
#include <span>
#include <string>
#include <vector>

#include <tbb/enumerable_thread_specific.h>

#include "core/error.hpp"
#include "surface/cell_loops.hpp"
#include "surface/cell_tile.hpp"
#include "surface/surface_common.hpp"

namespace levelset {

using namespace surface_detail;

namespace {

constexpr int kEdgeSlots = kBrickVoxels * 3;  // 1536; centroids follow

// One brick's output: built in the thread's Scratch, kept in its OutputArena.
struct BrickBuild {
  std::vector<Vec3d> vertices;  // owned edge vertices in slot order, then centroids
  std::vector<Vec3f> normals;
  std::vector<std::array<VertexKey, 3>> triangles;
  Neighborhood around{};
};
struct BrickOut {
  std::span<const Vec3d> vertices;
  std::span<const Vec3f> normals;
  std::span<const std::array<VertexKey, 3>> triangles;
  Neighborhood around{};
  SlotBits<kEdgeSlots> owned;
  std::uint32_t edge_vertices = 0;
  std::uint64_t cells = 0;
  std::uint32_t extra = 0;
};

// Per-thread scratch: the tile, its edge crossings, the brick being built and the arena that
// keeps the built bricks.
struct Scratch {
  CellTile tile;
  EdgeCrossings edges;
  BrickBuild build;
  OutputArena arena;
};

void process_brick(const NarrowBand& band, std::span<const float> decoded, std::uint32_t b, double iso,
                   Scratch& scratch, BrickOut& kept) {  // owned slots and counts go straight into kept
  CellTile& t = scratch.tile;
  const double h = band.voxel_size();
  ValidCells valid;
  BrickBuild& out = scratch.build;
  out.vertices.clear();
  out.normals.clear();
  out.triangles.clear();
  const Vec3d corner = begin_brick(band, b, iso, t, valid, out, decoded);
  out.triangles.reserve(2 * valid.mixed_cells + 8);

  // Edge crossings of the cells [0, 8)^3, and the vertices of the owned ones in slot order.
  scratch.edges.compute(t, valid, iso, 0);
  for (int z = 0; z < kBrickDim; ++z)
    for (int y = 0; y < kBrickDim; ++y) {
      std::uint32_t cr[3];
      valid.crossing_edges(y, z, cr);
      for (std::uint32_t bits = (cr[0] | cr[1] | cr[2]) & ValidCells::x_bits(0, kBrickDim); bits != 0; bits &= bits - 1) {
        const int x = std::countr_zero(bits) - 1;
        const int p = CellTile::index(x, y, z);
        for (int a = 0; a < 3; ++a) {
          if (!((cr[a] >> (x + 1)) & 1u) || !valid.edge_used(x, y, z, a)) continue;
          kept.owned.set(3 * local_index(x, y, z) + a);
          const double s = scratch.edges.at(p, a);
          out.vertices.push_back(corner + scratch.edges.point(x, y, z, a) * h);
          out.normals.push_back(normalized_f(corner_gradient(t, p) * (1.0 - s) + corner_gradient(t, p + kTileStride[a]) * s));
        }
      }
    }
  kept.edge_vertices = std::uint32_t(out.vertices.size());

  // Cells.
  std::array<Vec3d, 12> pos;
  std::array<VertexKey, 12> key;
  for (int z = 0; z < kBrickDim; ++z)
    for (int y = 0; y < kBrickDim; ++y)
      for (std::uint32_t bits = (valid.mixed_row(y, z) >> ValidCells::kH) & 0xffu; bits != 0; bits &= bits - 1) {
        const int x = std::countr_zero(bits);
        double a[8];
        const int p0 = CellTile::index(x, y, z);
        for (int i = 0; i < 8; ++i) a[i] = double(t.values[p0 + kCornerOffset[i]]) - iso;
        int m, d;
        cell::classify(a, m, d);
        if (m == 0 || m == 255) continue;
        ++kept.cells;
        const cell::LoopSet& ls = cell::loops_for(m, d);
        for (int l = 0; l < ls.loop_count; ++l) {
          const int n = ls.length[l];
          const std::uint8_t* edges = &ls.edges[ls.begin[l]];
          for (int i = 0; i < n; ++i) {
            const int e = edges[i];
            const int c = cell::edge_lower_corner(e);
            const int ex = x + (c & 1), ey = y + ((c >> 1) & 1), ez = z + ((c >> 2) & 1);
            key[i] = vertex_key(Neighborhood::slot(ex >> 3, ey >> 3, ez >> 3),
                                3 * local_index(ex & 7, ey & 7, ez & 7) + (e >> 2));
          }
          if (n == 3) {
            out.triangles.push_back({key[0], key[1], key[2]});
            continue;
          }
          for (int i = 0; i < n; ++i) {
            const int e = edges[i];
            const int c = cell::edge_lower_corner(e);
            pos[i] = scratch.edges.point(x + (c & 1), y + ((c >> 1) & 1), z + ((c >> 2) & 1), e >> 2);
          }
          if ((ls.doubled_face_loops >> l) & 1) {
            Vec3d c{};
            for (int i = 0; i < n; ++i) c += pos[i];
            c = c / double(n);
            const VertexKey ck = vertex_key(Neighborhood::slot(0, 0, 0), kEdgeSlots + int(kept.extra));
            out.vertices.push_back(corner + c * h);
            out.normals.push_back(normalized_f(gradient_at(t, c, x, y, z)));
            ++kept.extra;
            for (int i = 0; i < n; ++i) out.triangles.push_back({ck, key[i], key[(i + 1) % n]});
            continue;
          }
          const int s = best_fan_start(pos.data(), n);
          for (int i = 1; i + 1 < n; ++i)
            out.triangles.push_back({key[s], key[(s + i) % n], key[(s + i + 1) % n]});
        }
      }
  kept.around = out.around;
  kept.vertices = scratch.arena.keep(out.vertices);
  kept.normals = scratch.arena.keep(out.normals);
  kept.triangles = scratch.arena.keep(out.triangles);
}

}  // namespace

SurfaceResult marching_cubes(const NarrowBand& band, const MarchingCubesOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  check_iso(band, options.iso, "marching_cubes");
  const std::uint32_t nb = std::uint32_t(band.brick_count());
  std::vector<BrickOut> outs(nb);
  const std::vector<std::uint8_t> work = bricks_with_crossings(band, options.iso);
  tbb::enumerable_thread_specific<Scratch> scratch;
  // Each brick decoded once (its tile and its neighbours' tiles then copy rows).
  const DecodedBricks decoded = decode_bricks(band);
  for_brick_batches(nb, options.progress, "marching_cubes", [&](std::uint32_t b) {
    if (work[b]) process_brick(band, decoded.values(), b, options.iso, scratch.local(), outs[b]);
  });

  SurfaceResult r;
  for (const BrickOut& o : outs) r.extra_vertices += o.extra;
  const MergeOffsets m = merge_offsets(outs, r, "marching_cubes");
  auto remap = [&](std::uint32_t owner, int slot) {
    const BrickOut& o = outs[owner];
    return slot < kEdgeSlots ? m.vertex[owner] + o.owned.rank(slot)
                             : m.vertex[owner] + o.edge_vertices + std::uint32_t(slot - kEdgeSlots);
  };
  copy_merged(outs, m, remap, r);
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return r;
}

}  // namespace levelset
