#include "surface/surface_nets.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <chrono>
#include <cmath>
#include <optional>
#include <span>
#include <vector>

#include <tbb/enumerable_thread_specific.h>

#include "core/error.hpp"
#include "surface/cell_loops.hpp"
#include "surface/cell_tile.hpp"
#include "surface/surface_common.hpp"

namespace levelset {

using namespace surface_detail;

namespace {

// Vertex slots of a brick: 4 * local cell index + loop for the one vertex of a loop; split
// loops (see the header) have one vertex per loop edge at kSplitSlot0 + 12 * cell + edge.
constexpr int kLoopSlots = kBrickVoxels * 4;  // 2048
constexpr int kSplitSlot0 = kLoopSlots;

// One brick's output: built in the thread's Scratch, kept in its OutputArena.
struct BrickBuild {
  std::vector<Vec3d> vertices;  // loop vertices in slot order, then split-loop vertices in slot order
  std::vector<Vec3f> normals;
  std::vector<std::array<VertexKey, 3>> triangles;
  std::vector<std::array<VertexKey, 4>> quads;
  std::vector<std::uint16_t> split_slots;  // sorted, slot - kSplitSlot0
  Neighborhood around{};
};
struct BrickOut {
  std::span<const Vec3d> vertices;
  std::span<const Vec3f> normals;
  std::span<const std::array<VertexKey, 3>> triangles;
  std::span<const std::array<VertexKey, 4>> quads;
  Neighborhood around{};
  SlotBits<kLoopSlots> owned;
  std::span<const std::uint16_t> split_slots;
  std::uint32_t loop_vertices = 0;
  std::uint64_t cells = 0;
};

// The field at the corners of the owned cells that cross iso (voxel rows holding such corners
// only; other entries are stale): per voxel (phi - iso, central differences along x, y, z) in
// value units (per voxel), computed once per brick, row by row.
struct FieldTile {
  std::vector<std::array<float, 4>> f = std::vector<std::array<float, 4>>(CellTile::kSize);
  void compute(const CellTile& t, const ValidCells& valid, double iso) {
    constexpr int kRows = kBrickDim + 1;  // voxel rows y, z in [0, 9)
    std::array<std::uint16_t, kRows> need{};  // bit y of need[z]
    for (int z = 0; z < kBrickDim; ++z)
      for (int y = 0; y < kBrickDim; ++y)
        if ((valid.mixed_row(y, z) >> ValidCells::kH) & 0xffu) {
          const std::uint16_t two = std::uint16_t(3u << y);
          need[std::size_t(z)] |= two;
          need[std::size_t(z + 1)] |= two;
        }
    const float* v = t.values.data();
    for (int z = 0; z <= kBrickDim; ++z)
      for (std::uint32_t ys = need[std::size_t(z)]; ys != 0; ys &= ys - 1) {
        const int p = CellTile::index(0, std::countr_zero(ys), z);
        for (int x = 0; x <= kBrickDim; ++x) {
          const float* c = v + p + x;
          f[std::size_t(p + x)] = {float(double(*c) - iso), 0.5f * (c[kTileStride[0]] - c[-kTileStride[0]]),
                                   0.5f * (c[kTileStride[1]] - c[-kTileStride[1]]),
                                   0.5f * (c[kTileStride[2]] - c[-kTileStride[2]])};
        }
      }
  }
};

// One cell's field channels (phi - iso, gx, gy, gz) at its 8 corners, trilinearly
// interpolated at a local point f in [0, 1]^3. Single precision: one 4-lane vector per corner,
// and vertex positions need ~1e-6 voxel at most.
struct CellField {
  alignas(16) float v[8][4];
  CellField(const FieldTile& ft, int p0) {
    for (int i = 0; i < 8; ++i) {
      const std::array<float, 4>& c = ft.f[std::size_t(p0 + kCornerOffset[i])];
      for (int k = 0; k < 4; ++k) v[i][k] = c[std::size_t(k)];
    }
  }
  void eval(float fx, float fy, float fz, float out[4]) const {
    float r[4][4], q[2][4];
    for (int k = 0; k < 4; ++k)
      for (int c = 0; c < 4; ++c) r[k][c] = v[2 * k][c] + fx * (v[2 * k + 1][c] - v[2 * k][c]);
    for (int j = 0; j < 2; ++j)
      for (int c = 0; c < 4; ++c) q[j][c] = r[2 * j][c] + fy * (r[2 * j + 1][c] - r[2 * j][c]);
    for (int c = 0; c < 4; ++c) out[c] = q[0][c] + fz * (q[1][c] - q[0][c]);
  }
  // Newton steps from c (cell-local) along the interpolated gradient onto the trilinear zero
  // level, clamped to the cell. Stops after a step shorter than 1e-4 voxel: Newton converges
  // quadratically here, so the next step would be below float precision.
  Vec3d project(const Vec3d& start, int iterations) const {
    float x = float(start.x), y = float(start.y), z = float(start.z);
    for (int it = 0; it < iterations; ++it) {
      float f[4];
      eval(x, y, z, f);
      const float gg = f[1] * f[1] + f[2] * f[2] + f[3] * f[3];
      if (!(gg > 1e-12f)) break;
      const float k = f[0] / gg;
      x = std::clamp(x - k * f[1], 0.0f, 1.0f);
      y = std::clamp(y - k * f[2], 0.0f, 1.0f);
      z = std::clamp(z - k * f[3], 0.0f, 1.0f);
      if (f[0] * f[0] < 1e-8f * gg) break;  // step length |phi| / |grad| < 1e-4
    }
    return {double(x), double(y), double(z)};
  }
  Vec3f normal(const Vec3d& c) const {
    float f[4];
    eval(float(c.x), float(c.y), float(c.z), f);
    return normalized_f({double(f[1]), double(f[2]), double(f[3])});
  }
};

// Cell-local crossing point of cell edge e of the cell with tile index p0.
inline Vec3d crossing(const EdgeCrossings& edges, int p0, int e) {
  const int k = cell::edge_lower_corner(e), a = e >> 2;
  const double s = edges.at(p0 + kCornerOffset[k], a);
  return {a == 0 ? s : double(k & 1), a == 1 ? s : double((k >> 1) & 1), a == 2 ? s : double((k >> 2) & 1)};
}

inline Vec3d loop_centroid(const EdgeCrossings& edges, int p0, const cell::LoopSet& ls, int l) {
  Vec3d c{};
  for (int i = 0; i < ls.length[l]; ++i) c += crossing(edges, p0, ls.edges[ls.begin[l] + i]);
  return c / double(ls.length[l]);
}

const cell::LoopSet& classify_cell(const CellTile& t, int x, int y, int z, double iso) {
  double a[8];
  const int p0 = CellTile::index(x, y, z);
  for (int i = 0; i < 8; ++i) a[i] = double(t.values[p0 + kCornerOffset[i]]) - iso;
  int m, d;
  cell::classify(a, m, d);
  return cell::loops_for(m, d);
}

// Loops of a cell read from the band itself, nullptr unless all 8 corners are active: for the
// rare neighbour cell outside the tile (split test of a cell on the tile's low boundary).
const cell::LoopSet* classify_from_band(const NarrowBand& band, const Coord& c, double iso) {
  double a[8];
  for (int i = 0; i < 8; ++i) {
    const std::optional<float> v = band.value(c + Coord{i & 1, (i >> 1) & 1, (i >> 2) & 1});
    if (!v) return nullptr;
    a[i] = double(*v) - iso;
  }
  int m, d;
  cell::classify(a, m, d);
  return &cell::loops_for(m, d);
}

// Loops of the cell that must be split: the loop holds both segments of a face whose
// neighbouring cell (valid) also has a loop holding both. One vertex per loop on each side
// would join the two sheets crossing that face in one dual edge with 4 triangles.
std::uint8_t split_loops(const NarrowBand& band, const Coord& base, const CellTile& t, const ValidCells& valid,
                         int x, int y, int z, const cell::LoopSet& ls, double iso) {
  std::uint8_t split = 0;
  for (int l = 0; l < ls.loop_count; ++l)
    for (std::uint32_t faces = ls.doubled_faces[l]; faces != 0; faces &= faces - 1) {
      const int f = std::countr_zero(faces), a = f >> 1, step = (f & 1) ? 1 : -1;
      int n[3] = {x, y, z};
      n[a] += step;
      const cell::LoopSet* other = nullptr;
      if (n[a] >= -1) {
        if (valid.cell_valid(n[0], n[1], n[2])) other = &classify_cell(t, n[0], n[1], n[2], iso);
      } else {
        other = classify_from_band(band, base + Coord{n[0], n[1], n[2]}, iso);
      }
      if (other == nullptr) continue;
      bool doubled = false;
      for (int k = 0; k < other->loop_count; ++k) doubled |= ((other->doubled_faces[k] >> (f ^ 1)) & 1) != 0;
      if (doubled) {
        split |= std::uint8_t(1u << l);
        break;
      }
    }
  return split;
}

constexpr int kCells = ValidCells::kN * ValidCells::kN * ValidCells::kN;

// Per-thread scratch: the tile, its edge crossings and gradients, and the loops and split
// masks of the cells with min corner in [-1, 8)^3 that cross iso.
struct Scratch {
  CellTile tile;
  EdgeCrossings edges;
  FieldTile field;
  std::array<const cell::LoopSet*, kCells> loops{};
  std::array<std::uint8_t, kCells> split{};
  struct SplitVertex {
    std::uint16_t slot;
    Vec3d position;
    Vec3f normal;
  };
  std::vector<SplitVertex> split_vertices;
  BrickBuild build;
  OutputArena arena;
};

// Builds brick b's output in s.build (its counts and owned slots straight into `kept`).
void build_brick(const NarrowBand& band, std::uint32_t b, double iso, int iterations, Scratch& s, BrickOut& kept) {
  CellTile& t = s.tile;
  const double h = band.voxel_size();
  ValidCells valid;
  BrickBuild& out = s.build;
  out.vertices.clear();
  out.normals.clear();
  out.triangles.clear();
  out.quads.clear();
  out.split_slots.clear();
  const Vec3d corner = begin_brick(band, b, iso, t, valid, out);
  const Coord base = brick_origin(band.bricks()[b].coord);
  out.quads.reserve(valid.mixed_cells + 8);
  s.edges.compute(t, valid, iso, 0);
  s.field.compute(t, valid, iso);
  s.split_vertices.clear();
  auto world = [&](int x, int y, int z, const Vec3d& local) {
    return corner + (Vec3d{double(x), double(y), double(z)} + local) * h;
  };
  constexpr int kSelf = Neighborhood::slot(0, 0, 0);

  // Loops of every valid cell crossing iso; vertices of the owned ones (min corner in
  // [0, 8)^3), loop vertices in slot order.
  bool any_split = false;
  for (int z = -1; z < kBrickDim; ++z)
    for (int y = -1; y < kBrickDim; ++y)
      for (std::uint32_t bits = valid.mixed_row(y, z) >> (ValidCells::kH - 1); bits != 0; bits &= bits - 1) {
        const int x = std::countr_zero(bits) - 1;
        const cell::LoopSet& ls = classify_cell(t, x, y, z, iso);
        const int ci = ValidCells::index(x, y, z);
        s.loops[ci] = &ls;
        s.split[ci] = ls.doubled_face_loops ? split_loops(band, base, t, valid, x, y, z, ls, iso) : 0;
        any_split |= s.split[ci] != 0;
        if (ls.loop_count == 0 || x < 0 || y < 0 || z < 0) continue;
        ++kept.cells;
        const int p0 = CellTile::index(x, y, z);
        const CellField cf(s.field, p0);
        const int li = local_index(x, y, z);
        for (int l = 0; l < ls.loop_count; ++l) {
          const Vec3d centre = loop_centroid(s.edges, p0, ls, l);
          if (!((s.split[ci] >> l) & 1)) {
            const Vec3d c = cf.project(centre, iterations);
            kept.owned.set(4 * li + l);
            out.vertices.push_back(world(x, y, z, c));
            out.normals.push_back(cf.normal(c));
            continue;
          }
          // Split loop: one vertex per edge, between its crossing and the loop centre, and a
          // cap polygon through them in loop order.
          const int n = ls.length[l];
          std::array<Vec3d, 12> pos;
          std::array<VertexKey, 12> key;
          for (int i = 0; i < n; ++i) {
            const int e = ls.edges[ls.begin[l] + i];
            const Vec3d c = cf.project((crossing(s.edges, p0, e) + centre) * 0.5, iterations);
            const int slot = 12 * li + e;
            s.split_vertices.push_back({std::uint16_t(slot), world(x, y, z, c), cf.normal(c)});
            pos[std::size_t(i)] = c;
            key[std::size_t(i)] = vertex_key(kSelf, kSplitSlot0 + slot);
          }
          const int f = best_fan_start(pos.data(), n);
          for (int i = 1; i + 1 < n; ++i)
            out.triangles.push_back({key[std::size_t(f)], key[std::size_t((f + i) % n)], key[std::size_t((f + i + 1) % n)]});
        }
      }
  kept.loop_vertices = std::uint32_t(out.vertices.size());
  std::sort(s.split_vertices.begin(), s.split_vertices.end(),
            [](const Scratch::SplitVertex& a, const Scratch::SplitVertex& b) { return a.slot < b.slot; });
  for (const Scratch::SplitVertex& v : s.split_vertices) {
    out.split_slots.push_back(v.slot);
    out.vertices.push_back(v.position);
    out.normals.push_back(v.normal);
  }

  // The vertex of cell (x, y, z) (in [-1, 8)^3, crossing iso) on its cell edge e.
  auto vertex_on = [&](int x, int y, int z, int e) {
    const int ci = ValidCells::index(x, y, z);
    const int l = s.loops[ci]->loop_of_edge[e];
    const int owner = Neighborhood::slot(x < 0 ? -1 : 0, y < 0 ? -1 : 0, z < 0 ? -1 : 0);
    const int li = local_index(x & 7, y & 7, z & 7);
    return ((s.split[ci] >> l) & 1) ? vertex_key(owner, kSplitSlot0 + 12 * li + e) : vertex_key(owner, 4 * li + l);
  };

  // Quads around owned crossing edges.
  for (int z = 0; z < kBrickDim; ++z)
    for (int y = 0; y < kBrickDim; ++y) {
      std::uint32_t cr[3];
      valid.crossing_edges(y, z, cr);
      for (std::uint32_t& c : cr) c = (c & ValidCells::x_bits(0, kBrickDim)) >> 1;  // owned edges, bit x
      for (std::uint32_t bits = cr[0] | cr[1] | cr[2]; bits != 0; bits &= bits - 1) {
        const int x = std::countr_zero(bits);
        const bool p_in = double(t.values[std::size_t(CellTile::index(x, y, z))]) - iso < 0.0;
        for (int a = 0; a < 3; ++a) {
          if (!((cr[a] >> x) & 1u)) continue;
          const int bax = a == 0 ? 1 : 0, cax = a == 2 ? 1 : 2;
          static constexpr int kOrder[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
          std::array<VertexKey, 4> key;
          bool ok = true;
          for (int k = 0; k < 4 && ok; ++k) {
            int c[3] = {x, y, z};
            c[bax] -= kOrder[k][0];
            c[cax] -= kOrder[k][1];
            ok = valid.at(c[0], c[1], c[2]);
            if (ok) key[std::size_t(k)] = vertex_on(c[0], c[1], c[2], 4 * a + kOrder[k][0] + 2 * kOrder[k][1]);
          }
          if (!ok) continue;
          // kOrder turns about +a for x and z and about -a for y; outside lies at +a when p is in.
          if ((a == 1) == p_in) std::swap(key[1], key[3]);
          out.quads.push_back(key);
        }
      }
    }
  if (!any_split) return;

  // Seams where a split loop meets its neighbour across a face: each owned cell closes the
  // gaps on its three lower faces. The segment ea -> eb (this cell's loop order) is traversed
  // eb -> ea by the lower cell; the seam runs v(eb), v(ea) here, then v(ea), v(eb) there.
  for (int z = 0; z < kBrickDim; ++z)
    for (int y = 0; y < kBrickDim; ++y)
      for (std::uint32_t bits = (valid.mixed_row(y, z) >> ValidCells::kH) & 0xffu; bits != 0; bits &= bits - 1) {
        const int x = std::countr_zero(bits);
        const int ci = ValidCells::index(x, y, z);
        const cell::LoopSet& ls = *s.loops[ci];
        for (int l = 0; l < ls.loop_count; ++l) {
          const int n = ls.length[l];
          for (int i = 0; i < n; ++i) {
            const int ea = ls.edges[ls.begin[l] + i], eb = ls.edges[ls.begin[l] + (i + 1) % n];
            const int f = cell::common_face(ea, eb);
            if (f < 0 || (f & 1) != 0) continue;
            const int a = f >> 1;
            int c[3] = {x, y, z};
            c[a] -= 1;
            if (!valid.at(c[0], c[1], c[2])) continue;
            const int cj = ValidCells::index(c[0], c[1], c[2]);
            const int la = cell::edge_from_lower_neighbor(ea, a), lb = cell::edge_from_lower_neighbor(eb, a);
            const bool here = (s.split[ci] >> l) & 1;
            const bool there = (s.split[cj] >> s.loops[cj]->loop_of_edge[la]) & 1;
            if (!here && !there) continue;
            const VertexKey ha = vertex_on(x, y, z, ea), hb = vertex_on(x, y, z, eb);
            const VertexKey ta = vertex_on(c[0], c[1], c[2], la), tb = vertex_on(c[0], c[1], c[2], lb);
            if (here && there) out.quads.push_back({hb, ha, ta, tb});
            else if (here) out.triangles.push_back({hb, ha, ta});
            else out.triangles.push_back({ha, ta, tb});
          }
        }
      }
}

void process_brick(const NarrowBand& band, std::uint32_t b, double iso, int iterations, Scratch& s, BrickOut& kept) {
  build_brick(band, b, iso, iterations, s, kept);
  const BrickBuild& out = s.build;
  kept.around = out.around;
  kept.vertices = s.arena.keep(out.vertices);
  kept.normals = s.arena.keep(out.normals);
  kept.triangles = s.arena.keep(out.triangles);
  kept.quads = s.arena.keep(out.quads);
  kept.split_slots = s.arena.keep(out.split_slots);
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
  auto remap = [&](std::uint32_t owner, int slot) {
    const BrickOut& o = outs[owner];
    if (slot < kSplitSlot0) return m.vertex[owner] + o.owned.rank(slot);
    const auto it = std::lower_bound(o.split_slots.begin(), o.split_slots.end(), std::uint16_t(slot - kSplitSlot0));
    if (it == o.split_slots.end() || *it != std::uint16_t(slot - kSplitSlot0))
      throw Error(ErrorCode::Corrupt, "surface_nets", "internal: a split-loop vertex is missing");
    return m.vertex[owner] + o.loop_vertices + std::uint32_t(it - o.split_slots.begin());
  };
  copy_merged(outs, m, remap, r);
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return r;
}

}  // namespace levelset
