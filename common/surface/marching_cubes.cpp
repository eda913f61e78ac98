#include "surface/marching_cubes.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <chrono>
#include <cmath>
#include <memory>
#include <new>
#include <span>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

#include <tbb/enumerable_thread_specific.h>

#include "core/error.hpp"
#include "core/uninitialized_vector.hpp"
#include "surface/band_masks.hpp"
#include "surface/cell_loops.hpp"
#include "surface/cell_tile.hpp"
#include "surface/surface_common.hpp"

namespace levelset {

using namespace surface_detail;

namespace {

constexpr int kEdgeSlots = kBrickVoxels * 3;  // 1536

// The counting pass's record of one brick: the edge slots that own a vertex and what the brick
// writes. The writing pass writes at the prefix sums, straight into the result.
struct BrickCount {
  SlotBits<kEdgeSlots> owned;
  std::uint32_t edge_vertices = 0;
  std::uint32_t centres = 0;  // loop-centre vertices, after the edge vertices
  std::uint32_t triangles = 0;
  std::uint32_t cells = 0;
  Neighborhood around{};  // what the tile was gathered with: pass 2 gathers without searching
  NeighborSigns signs{};
};

// Per-thread scratch: the tile, its cell classes, edge crossings and the crossing edges'
// global vertex indices (tile index * 3 + axis).
struct Scratch {
  CellTile tile;
  ValidCells valid;
  EdgeCrossings edges;
  std::vector<std::uint32_t> vertex_of_edge = std::vector<std::uint32_t>(3 * CellTile::kSize);
};

// The grid edges from voxels in [0, 8)^3 that cross iso and belong to a contoured cell, in slot
// order (slot 3 local_index + axis, as the counting pass recorded them): f(x, y, z, axis).
template <typename F>
void for_each_owned_edge(const SlotBits<kEdgeSlots>& owned, F&& f) {
  for (int w = 0; w < SlotBits<kEdgeSlots>::kWords; ++w)
    for (std::uint64_t bits = owned.words[std::size_t(w)]; bits != 0; bits &= bits - 1) {
      const int slot = 64 * w + std::countr_zero(bits), n = slot / 3;
      f(n & 7, (n >> 3) & 7, n >> 6, slot - 3 * n);
    }
}

// The contoured cells of [0, 8)^3 that cross iso, in cell order: f(x, y, z, loops). The
// inside mask comes from the row bits; corners(x, y, z, a) fills a[8] with the values minus
// iso, called only for a cell with an ambiguous face (its loops depend on the face decisions).
template <typename Corners, typename F>
void for_each_mixed_cell(const ValidCells& valid, Corners&& corners, F&& f) {
  const cell::LoopLookup& loops = cell::loop_lookup();
  for (int z = 0; z < kBrickDim; ++z)
    for (int y = 0; y < kBrickDim; ++y) {
      const std::uint32_t rows[4] = {valid.inside_rows[std::size_t(ValidCells::row(y, z))],
                                     valid.inside_rows[std::size_t(ValidCells::row(y + 1, z))],
                                     valid.inside_rows[std::size_t(ValidCells::row(y, z + 1))],
                                     valid.inside_rows[std::size_t(ValidCells::row(y + 1, z + 1))]};
      for (std::uint32_t bits = (valid.mixed_row(y, z) >> ValidCells::kH) & 0xffu; bits != 0; bits &= bits - 1) {
        const int x = std::countr_zero(bits);
        // Corner i's inside bit is bit x + (i & 1) of row i >> 1: two corners per row.
        const int at = x + ValidCells::kH;
        const int m = int(((rows[0] >> at) & 3u) | (((rows[1] >> at) & 3u) << 2) | (((rows[2] >> at) & 3u) << 4) |
                          (((rows[3] >> at) & 3u) << 6));
        int d = 0;
        if (const int ambiguous = loops.ambiguous[m]; ambiguous != 0) {
          double a[8];
          corners(x, y, z, a);
          d = cell::face_decisions(a, ambiguous);
        }
        f(x, y, z, loops.at(m, d));
      }
    }
}

// Per cell edge e: its lower corner's offset and its slot (tile index offset * 3 + axis) in
// the per-edge arrays (EdgeCrossings::s, Scratch::vertex_of_edge), relative to the cell's p0.
struct CellEdge {
  std::int8_t dx, dy, dz, axis;
  int slot;
};
constexpr std::array<CellEdge, 12> make_cell_edges() {
  std::array<CellEdge, 12> out{};
  for (int e = 0; e < 12; ++e) {
    const int c = cell::edge_lower_corner(e);
    out[std::size_t(e)] = {std::int8_t(c & 1), std::int8_t((c >> 1) & 1), std::int8_t((c >> 2) & 1),
                           std::int8_t(e >> 2), 3 * kCornerOffset[c] + (e >> 2)};
  }
  return out;
}
constexpr std::array<CellEdge, 12> kCellEdges = make_cell_edges();

// Pass 1 from the masks alone: the owned edges and, per contoured cell, its loop set's
// counts (values are read only for a cell with an ambiguous face, whose loops depend on them).
void count_brick(const NarrowBand& band, const DecodedBand& decoded, std::uint32_t b, double iso, Scratch& s,
                 BrickCount& c) {
  c.around = brick_neighborhood(band, b);
  c.signs = resolve_neighbor_signs(band, c.around, -CellTile::kHalo, CellTile::kDim - CellTile::kHalo);
  ValidCells& valid = s.valid;
  cell_masks(band, decoded, c.around, c.signs, valid);
  for (int z = 0; z < kBrickDim; ++z)
    for (int y = 0; y < kBrickDim; ++y) {
      const std::uint32_t bits = valid.owned_edges(y, z);
      c.owned.set_bits(3 * local_index(0, y, z), bits);
      c.edge_vertices += std::uint32_t(std::popcount(bits));
    }
  c.owned.finish();
  for_each_mixed_cell(
      valid,
      [&](int x, int y, int z, double* a) {
        for (int i = 0; i < 8; ++i)
          a[i] = corner_value(decoded, c.around, x + (i & 1), y + ((i >> 1) & 1), z + ((i >> 2) & 1), iso);
      },
      [&](int, int, int, const cell::LoopSet& ls) {
        ++c.cells;
        c.triangles += ls.fan_triangles;
        c.centres += ls.centre_vertices;
      });
}

// Where each brick's output starts in the result (bricks + 1 entries each).
struct Bases {
  std::vector<std::uint32_t> vertex;
  std::vector<std::uint64_t> triangle;
};

// Writes brick b's vertices, normals and triangles (global indices) at its bases; the same
// enumeration as count_brick, so the ranks of the owned slots are the write positions.
void write_brick(const NarrowBand& band, const DecodedBand& decoded, std::uint32_t b, double iso,
                 std::span<const BrickCount> counts, const Bases& at, Scratch& s, SurfaceResult& r) {
  regather_cell_tile(band, counts[b].around, counts[b].signs, s.tile, decoded.values.values());
  s.valid.compute(s.tile, iso);
  const CellTile& t = s.tile;
  const Coord base = brick_origin(band.bricks()[b].coord);
  const Vec3d corner = band.origin() + Vec3d{double(base.x), double(base.y), double(base.z)} * band.voxel_size();
  const double h = band.voxel_size();
  // Each crossing edge's vertex index once (the cells' loops reference an edge up to 4 times):
  // its owner brick's first vertex plus the edge's rank among the owner's owned slots. Both
  // ends of a crossing edge are active, so the owner is allocated.
  // The brick's own edges come in slot order, so their rank is a running count.
  const SlotBits<kEdgeSlots>& own = counts[b].owned;
  std::uint32_t own_rank = 0;
  s.edges.compute(t, s.valid, iso, 0, [&](int x, int y, int z, int a, int p) {
    if (((x | y | z) & kBrickDim) == 0) {
      s.vertex_of_edge[std::size_t(3 * p + a)] = at.vertex[b] + own_rank;
      own_rank += own.test(3 * local_index(x, y, z) + a) ? 1u : 0u;
      return;
    }
    const std::uint32_t owner = t.around[std::size_t(Neighborhood::slot(x >> 3, y >> 3, z >> 3))];
    s.vertex_of_edge[std::size_t(3 * p + a)] =
        at.vertex[owner] + counts[owner].owned.rank(3 * local_index(x & 7, y & 7, z & 7) + a);
  });
  Vec3d* vertex = r.mesh.vertices.data() + at.vertex[b];
  Vec3f* normal = r.normals.data() + at.vertex[b];
  // The two passes enumerate the same data the same way; a difference is a bug, not input,
  // and must not write outside the brick's range.
  const Vec3d* const vertex_end = r.mesh.vertices.data() + at.vertex[b + 1];
  const std::array<std::uint32_t, 3>* const tri_end = r.mesh.triangles.data() + at.triangle[b + 1];
  auto differs = [] { return std::logic_error("marching_cubes: brick output differs from its count"); };
  for_each_owned_edge(counts[b].owned, [&](int x, int y, int z, int a) {
    if (vertex == vertex_end) throw differs();
    const int p = CellTile::index(x, y, z);
    const double u = s.edges.at(p, a);
    *vertex++ = corner + s.edges.point(x, y, z, a) * h;
    *normal++ = normalized_f(corner_gradient(t, p) * (1.0 - u) + corner_gradient(t, p + kTileStride[a]) * u);
  });
  std::uint32_t centre = at.vertex[b] + counts[b].edge_vertices;
  std::array<std::uint32_t, 3>* tri = r.mesh.triangles.data() + at.triangle[b];
  std::array<Vec3d, 12> pos;
  std::array<std::uint32_t, 24> index;  // a loop's vertex indices, twice (fans wrap without %)
  auto corners = [&](int x, int y, int z, double* a) {
    const int p0 = CellTile::index(x, y, z);
    for (int i = 0; i < 8; ++i) a[i] = double(t.values[p0 + kCornerOffset[i]]) - iso;
  };
  for_each_mixed_cell(s.valid, corners, [&](int x, int y, int z, const cell::LoopSet& ls) {
    const int p0 = CellTile::index(x, y, z);
    if (tri_end - tri < ls.fan_triangles || vertex_end - vertex < ls.centre_vertices) throw differs();
    const std::uint32_t* const cell_vertex = s.vertex_of_edge.data() + 3 * p0;
    const double* const cell_s = s.edges.s.data() + 3 * p0;
    for (int l = 0; l < ls.loop_count; ++l) {
      const int n = ls.length[l];
      const std::uint8_t* edges = &ls.edges[ls.begin[l]];
      for (int i = 0; i < n; ++i) index[i] = index[i + n] = cell_vertex[kCellEdges[edges[i]].slot];
      if (n > 3)
        for (int i = 0; i < n; ++i) {  // EdgeCrossings::point of the edge
          const CellEdge& e = kCellEdges[edges[i]];
          pos[i] = {double(x + e.dx), double(y + e.dy), double(z + e.dz)};
          pos[i][e.axis] += cell_s[e.slot];
        }
      if (n == 3) {
        *tri++ = {index[0], index[1], index[2]};
        continue;
      }
      if ((ls.doubled_face_loops >> l) & 1) {
        Vec3d c{};
        for (int i = 0; i < n; ++i) c += pos[i];
        c = c / double(n);
        *vertex++ = corner + c * h;
        *normal++ = normalized_f(gradient_at(t, c, x, y, z));
        for (int i = 0; i < n; ++i) *tri++ = {centre, index[i], index[i + 1]};
        ++centre;
        continue;
      }
      const int f = best_fan_start(pos.data(), n);
      for (int i = 1; i + 1 < n; ++i) *tri++ = {index[f], index[f + i], index[f + i + 1]};
    }
  });
  if (vertex != vertex_end || tri != tri_end) throw differs();
}

}  // namespace

SurfaceResult marching_cubes(const NarrowBand& band, const MarchingCubesOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  check_iso(band, options.iso, "marching_cubes");
  const std::uint32_t nb = std::uint32_t(band.brick_count());
  tbb::enumerable_thread_specific<Scratch> scratch;
  // Each brick decoded once with its inside mask: pass 1 counts from the masks, pass 2 gathers
  // tiles by row copies and writes into the sized result. No per-brick output buffers and no
  // copy (those were ~100 MB of fresh memory per call at R = 512; page faults are slow).
  const DecodedBand decoded = decode_band(band, options.iso);
  // Not value-initialised (a serial zeroing pass over ~430 bytes per brick): the counting pass
  // constructs every brick's entry, in parallel.
  const UninitializedArray<BrickCount> count_store(nb);
  prefault_for_write(count_store.data(), nb * sizeof(BrickCount));
  const std::span<BrickCount> counts(count_store.data(), nb);
  for_brick_batches(nb, options.progress, "marching_cubes", [&](std::uint32_t b) {
    BrickCount* c = new (&counts[b]) BrickCount{};
    if (decoded.work[b]) count_brick(band, decoded, b, options.iso, scratch.local(), *c);
  }, 0.0, 0.3);

  SurfaceResult r;
  Bases at{std::vector<std::uint32_t>(nb + 1, 0), std::vector<std::uint64_t>(nb + 1, 0)};
  std::uint64_t vertices = 0;
  for (std::uint32_t b = 0; b < nb; ++b) {
    at.vertex[b] = std::uint32_t(vertices);
    vertices += std::uint64_t(counts[b].edge_vertices) + counts[b].centres;
    if (vertices >= 0xffffffffull) throw Error(ErrorCode::LimitExceeded, "marching_cubes", "more than 2^32 - 1 vertices");
    at.triangle[b + 1] = at.triangle[b] + counts[b].triangles;
    r.extra_vertices += counts[b].centres;
    r.cells_with_surface += counts[b].cells;
  }
  at.vertex[nb] = std::uint32_t(vertices);
  size_result(r, vertices, at.triangle[nb]);
  for_brick_batches(nb, options.progress, "marching_cubes", [&](std::uint32_t b) {
    if (decoded.work[b]) write_brick(band, decoded, b, options.iso, counts, at, scratch.local(), r);
  }, 0.3, 1.0);
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return r;
}

}  // namespace levelset
