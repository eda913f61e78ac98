#include "surface/marching_cubes.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <chrono>
#include <cmath>
#include <string>

#include <tbb/enumerable_thread_specific.h>

#include "core/error.hpp"
#include "surface/cell_loops.hpp"
#include "surface/cell_tile.hpp"
#include "surface/surface_common.hpp"

namespace levelset {

using namespace surface_detail;

namespace {

constexpr int kEdgeSlots = kBrickVoxels * 3;  // 1536
constexpr int kSlotBits = 12;

struct BrickOut {
  std::vector<Vec3d> vertices;   // owned edge vertices in slot order, then centroids
  std::vector<Vec3f> normals;
  std::vector<std::array<std::uint64_t, 3>> triangles;  // owner << 12 | slot
  SlotBits<kEdgeSlots> owned;
  std::uint32_t edge_vertices = 0;
  std::uint64_t cells = 0;
  std::uint32_t extra = 0;
};

void process_brick(const NarrowBand& band, std::uint32_t b, double iso, CellTile& t,
                   BrickOut& out) {
  gather_cell_tile(band, b, t);
  const Coord base = brick_origin(band.bricks()[b].coord);
  const double h = band.voxel_size();
  const Vec3d org = band.origin();
  ValidCells valid;
  valid.compute(t, iso);

  // Owned edge vertices.
  for (int z = 0; z < kBrickDim; ++z)
    for (int y = 0; y < kBrickDim; ++y) {
      std::uint32_t cr[3];
      valid.crossing_edges(y, z, cr);
      for (std::uint32_t bits = cr[0] | cr[1] | cr[2]; bits != 0; bits &= bits - 1) {
        const int x = std::countr_zero(bits);
        for (int a = 0; a < 3; ++a) {
          if (!((cr[a] >> x) & 1u)) continue;
          if (!valid.edge_used(x, y, z, a)) continue;
          out.owned.set(3 * local_index(x, y, z) + a);
          const EdgePoint e = edge_point(t, x, y, z, a, iso);
          out.vertices.push_back(org + (Vec3d{double(base.x), double(base.y), double(base.z)} + e.local) * h);
          out.normals.push_back(e.normal);
        }
      }
    }
  out.edge_vertices = std::uint32_t(out.vertices.size());

  // Cells.
  std::array<Vec3d, 12> pos;
  std::array<std::uint64_t, 12> key;
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
        ++out.cells;
        const cell::LoopSet& ls = cell::loops_for(m, d);
        for (int l = 0; l < ls.loop_count; ++l) {
          const int n = ls.length[l];
          for (int i = 0; i < n; ++i) {
            const int e = ls.edges[ls.begin[l] + i];
            const int c = cell::edge_lower_corner(e);
            const int ex = x + (c & 1), ey = y + ((c >> 1) & 1), ez = z + ((c >> 2) & 1);
            const int ax = e >> 2;
            pos[i] = edge_point_position(t, ex, ey, ez, ax, iso);
            const int owner = CellTile::neighbor_slot(ex >> 3, ey >> 3, ez >> 3);
            key[i] = (std::uint64_t(t.around[owner]) << kSlotBits) |
                     std::uint64_t(3 * local_index(ex & 7, ey & 7, ez & 7) + ax);
          }
          if (n == 3) {
            out.triangles.push_back({key[0], key[1], key[2]});
            continue;
          }
          if ((ls.doubled_face_loops >> l) & 1) {
            Vec3d c{};
            Vec3f nrm{};
            for (int i = 0; i < n; ++i) c += pos[i];
            c = c / double(n);
            const Vec3d g = gradient_at(t, c, x, y, z);
            nrm = normalized_f(g);
            const std::uint64_t ck = (std::uint64_t(b) << kSlotBits) | std::uint64_t(kEdgeSlots + out.extra);
            out.vertices.push_back(org + (Vec3d{double(base.x), double(base.y), double(base.z)} + c) * h);
            out.normals.push_back(nrm);
            ++out.extra;
            for (int i = 0; i < n; ++i) out.triangles.push_back({ck, key[i], key[(i + 1) % n]});
            continue;
          }
          const int s = best_fan_start(pos.data(), n);
          for (int i = 1; i + 1 < n; ++i)
            out.triangles.push_back({key[s], key[(s + i) % n], key[(s + i + 1) % n]});
        }
      }
}

}  // namespace

SurfaceResult marching_cubes(const NarrowBand& band, const MarchingCubesOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  check_iso(band, options.iso, "marching_cubes");
  const std::uint32_t nb = std::uint32_t(band.brick_count());
  std::vector<BrickOut> outs(nb);
  tbb::enumerable_thread_specific<CellTile> tiles;
  for_brick_batches(nb, options.progress, "marching_cubes", [&](std::uint32_t b) {
    process_brick(band, b, options.iso, tiles.local(), outs[b]);
  });

  SurfaceResult r;
  for (const BrickOut& o : outs) r.extra_vertices += o.extra;
  const MergeOffsets m = merge_offsets(outs, r, "marching_cubes");
  auto remap = [&](std::uint64_t k) {
    const std::uint32_t owner = std::uint32_t(k >> kSlotBits);
    const int slot = int(k & ((1u << kSlotBits) - 1));
    const BrickOut& o = outs[owner];
    return slot < kEdgeSlots ? m.vertex[owner] + o.owned.rank(slot)
                             : m.vertex[owner] + o.edge_vertices + std::uint32_t(slot - kEdgeSlots);
  };
  copy_merged(outs, m, remap, r);
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return r;
}

}  // namespace levelset
