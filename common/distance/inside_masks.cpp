#include "distance/inside_masks.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <optional>
#include <span>
#include <string>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "core/error.hpp"
#include "io/validate_mesh.hpp"
#include "distance/brick_winding.hpp"
#include "distance/grid_crossings.hpp"
#include "distance/open_edges.hpp"

namespace levelset {

namespace {

constexpr std::size_t kBatchBricks = 4096;

std::size_t find_brick(const BrickTriangleLists& lists, const Coord& b) {
  const std::size_t nb = lists.bricks.size();
  if (!brick_in_range(b)) return nb;
  const std::uint64_t key = brick_key(b);
  auto it = std::lower_bound(lists.bricks.begin(), lists.bricks.end(), key,
                             [](const Coord& c, std::uint64_t k) { return brick_key(c) < k; });
  return it != lists.bricks.end() && brick_key(*it) == key ? std::size_t(it - lists.bricks.begin())
                                                           : nb;
}

// Open edges (open_edges.hpp) per triangle, and the bricks near them: those a triangle with an
// open edge comes near (its bounding box), and the listed bricks within kOpenReach bricks of
// those (reach >= 16 voxels; beyond it the continuous part of w changes by well under 1/2
// across a brick).
constexpr int kOpenReach = 2;

struct OpenEdgeInfo {
  std::vector<std::uint8_t> triangle_edges;  // bit k: edge (f[k], f[k+1]) is open
  std::vector<bool> near_brick;
  std::uint64_t count = 0;
};

OpenEdgeInfo find_open_edges(const TriangleMesh& mesh, std::span<const Vec3d> grid_vertices,
                             std::span<const GridTriangle> grid, const BrickTriangleLists& lists) {
  const std::size_t nt = mesh.triangles.size(), nb = lists.bricks.size();
  OpenEdgeInfo info;
  info.near_brick.assign(nb, false);
  std::vector<bool> counts(nt);
  for (std::size_t t = 0; t < nt; ++t)
    counts[t] =
        grid[t].normal_sign[0] != 0 || grid[t].normal_sign[1] != 0 || grid[t].normal_sign[2] != 0;
  const std::vector<std::uint32_t> welded = weld_exact(grid_vertices);
  const auto open = open_edges(mesh, welded, counts);
  info.count = open.size();
  if (open.empty()) return info;
  info.triangle_edges.assign(nt, 0);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, nt, 1024), [&](const auto& r) {
    for (std::size_t t = r.begin(); t != r.end(); ++t) {
      if (!counts[t]) continue;
      const auto& f = mesh.triangles[t];
      for (int k = 0; k < 3; ++k) {
        const std::uint32_t a = welded[f[k]], b = welded[f[(k + 1) % 3]];
        if (std::binary_search(open.begin(), open.end(),
                               std::array<std::uint32_t, 2>{std::min(a, b), std::max(a, b)}))
          info.triangle_edges[t] |= std::uint8_t(1u << k);
      }
    }
  });
  // Cores: the listed bricks whose voxel-centre box, grown by one voxel, meets the bounding box
  // of a triangle with an open edge (found from the triangles, so the choice does not depend on
  // the lists' margin; a big border triangle marks every brick along it, as beside a wide
  // sheet the continuous part varies across bricks far from the edge itself).
  std::vector<bool> core(nb, false);
  for (std::size_t t = 0; t < nt; ++t) {
    if (!info.triangle_edges[t]) continue;
    const GridTriangle& g = grid[t];
    Coord lo, hi;
    for (int a = 0; a < 3; ++a) {
      const double mn = std::min({g.corner[0][a], g.corner[1][a], g.corner[2][a]}) - 1.0;
      const double mx = std::max({g.corner[0][a], g.corner[1][a], g.corner[2][a]}) + 1.0;
      const double lim = double(kVoxelCoordLimit - 1);
      lo[a] = int(std::floor(std::clamp(mn, -lim, lim))) >> kBrickLog2;
      hi[a] = int(std::floor(std::clamp(mx, -lim, lim))) >> kBrickLog2;
    }
    for (int z = lo.z; z <= hi.z; ++z)
      for (int y = lo.y; y <= hi.y; ++y)
        for (int x = lo.x; x <= hi.x; ++x) {
          const std::size_t j = find_brick(lists, Coord{x, y, z});
          if (j < nb) core[j] = true;
        }
  }
  for (std::size_t i = 0; i < nb; ++i) {
    if (!core[i]) continue;
    for (int dz = -kOpenReach; dz <= kOpenReach; ++dz)
      for (int dy = -kOpenReach; dy <= kOpenReach; ++dy)
        for (int dx = -kOpenReach; dx <= kOpenReach; ++dx) {
          const std::size_t j = find_brick(lists, lists.bricks[i] + Coord{dx, dy, dz});
          if (j < nb) info.near_brick[j] = true;
        }
  }
  return info;
}

// The open edges that meet the brick's voxel-centre box grown by kRimReach voxels (all that
// inside_adaptive reads: its 8^3 block looks half its size around), in brick-local grid
// coordinates. Taken from the brick's own list where its margin covers that box (the lists
// hold every triangle within the margin, Euclidean, of the box), else from its 26 neighbours'
// too.
constexpr double kRimReach = 0.5 * kBrickDim;

void gather_rims(const BrickTriangleLists& lists, std::size_t i, std::span<const GridTriangle> grid,
                 const OpenEdgeInfo& info, double voxel_size, std::vector<std::uint64_t>& scratch,
                 std::vector<OpenSegment>& rims) {
  rims.clear();
  scratch.clear();
  const bool own_list_covers = lists.margin >= kRimReach * std::sqrt(3.0) * voxel_size * (1 + 1e-9);
  const int reach = own_list_covers ? 0 : 1;
  for (int dz = -reach; dz <= reach; ++dz)
    for (int dy = -reach; dy <= reach; ++dy)
      for (int dx = -reach; dx <= reach; ++dx) {
        const std::size_t j = find_brick(lists, lists.bricks[i] + Coord{dx, dy, dz});
        if (j == lists.bricks.size()) continue;
        for (std::uint64_t k = lists.offsets[j]; k < lists.offsets[j + 1]; ++k) {
          const std::uint32_t t = lists.triangles[k];
          for (int e = 0; e < 3; ++e)
            if ((info.triangle_edges[t] >> e) & 1u)
              scratch.push_back(std::uint64_t(t) * 4 + std::uint64_t(e));
        }
      }
  if (reach > 0) {  // a triangle may be listed by several of the 27 bricks
    std::sort(scratch.begin(), scratch.end());
    scratch.erase(std::unique(scratch.begin(), scratch.end()), scratch.end());
  }
  const Coord o = brick_origin(lists.bricks[i]);
  const Vec3d origin{double(o.x), double(o.y), double(o.z)};
  const Vec3d lo{-kRimReach, -kRimReach, -kRimReach};
  const Vec3d hi = Vec3d{1, 1, 1} * (kBrickDim - 1 + kRimReach);
  for (std::uint64_t code : scratch) {
    const GridTriangle& g = grid[code / 4];
    const int e = int(code % 4);
    const OpenSegment segment{g.corner[e] - origin, g.corner[(e + 1) % 3] - origin};
    if (segment_meets_box(segment[0], segment[1], lo, hi)) rims.push_back(segment);
  }
}

void validate(const TriangleMesh& mesh, const LazyWindingTree& tree,
              const BrickTriangleLists& lists, const InsideMasksOptions& options) {
  const GridFrame& f = options.frame;
  if (!(std::isfinite(f.voxel_size) && f.voxel_size > 0.0) || !isfinite(f.origin))
    throw Error(ErrorCode::InvalidArgument, "frame",
                "voxel size must be finite and > 0, origin finite");
  if (!(options.beta > 0.0) || !std::isfinite(options.beta))
    throw Error(ErrorCode::InvalidArgument, "beta", "must be finite and > 0");
  const std::size_t nt = mesh.triangles.size();
  validate_mesh(mesh);
  if (tree.given() && tree.given()->order.size() != nt)
    throw Error(ErrorCode::InvalidArgument, "winding tree",
                "built from a mesh with " + std::to_string(tree.given()->order.size()) +
                    " triangles, not " + std::to_string(nt));
  const std::size_t nb = lists.bricks.size();
  if (lists.offsets.size() != nb + 1 || lists.offsets.front() != 0 ||
      lists.offsets.back() != lists.triangles.size())
    throw Error(ErrorCode::InvalidArgument, "brick lists",
                "offsets do not match bricks and triangles");
  for (std::size_t i = 0; i < nb; ++i) {
    if (lists.offsets[i] > lists.offsets[i + 1])
      throw Error(ErrorCode::InvalidArgument, "brick lists",
                  "offsets decrease at brick " + std::to_string(i));
    if (!brick_in_range(lists.bricks[i]))
      throw Error(ErrorCode::InvalidArgument, "brick lists",
                  "brick " + std::to_string(i) + " out of range");
  }
  for (std::uint32_t t : lists.triangles)
    if (t >= nt)
      throw Error(ErrorCode::InvalidArgument, "brick lists",
                  "triangle index " + std::to_string(t) + " out of range");
}

// Closed meshes (no open edge): exact integer winding numbers without the tree. Per brick, the
// winding numbers relative to its base voxel (relative_winding) and the changes from its base
// to the bases of its +x, +y, +z neighbours (the base's line plus the edge across the face);
// then, per face-connected group of bricks, one ray from a base anchors them all.
// A brick whose relative winding numbers span more levels than this (many nested or stacked
// shells) keeps its 512 numbers instead of a mask per level: memory stays bounded per brick.
constexpr int kMaxLevels = 16;

struct RelativeBrick {
  std::vector<int> rel;                   // deep bricks only (more than kMaxLevels levels)
  int lo = 0;                             // lowest relative winding number in the brick
  std::vector<BrickMask> levels;          // levels[k]: voxels with relative w >= lo + 1 + k
  std::array<std::size_t, 3> next{};      // index of the +axis neighbour (nb: none)
  std::array<int, 3> step{};              // w(neighbour's base) - w(base)
};

RelativeBrick relative_brick(std::span<const GridTriangle> grid, const BrickTriangleLists& lists,
                             std::size_t i, BrickCrossings& scratch) {
  auto ids = [&](std::size_t k) {
    return std::span<const std::uint32_t>(lists.triangles.data() + lists.offsets[k],
                                          lists.offsets[k + 1] - lists.offsets[k]);
  };
  const std::size_t nb = lists.bricks.size();
  const Coord& brick = lists.bricks[i];
  const std::array<int, kBrickVoxels> rel = relative_winding(grid, ids(i), brick, scratch);
  RelativeBrick out;
  const auto [lo, hi] = std::minmax_element(rel.begin(), rel.end());
  out.lo = *lo;
  if (*hi - *lo > kMaxLevels) {
    out.rel.assign(rel.begin(), rel.end());
  } else {
    out.levels.resize(std::size_t(*hi - *lo));
    for (int n = 0; n < kBrickVoxels; ++n)
      for (int k = 0; k < rel[n] - out.lo; ++k) out.levels[std::size_t(k)].set(n);
  }
  for (int a = 0; a < 3; ++a) {
    Coord step{0, 0, 0};
    step[a] = 1;
    out.next[a] = find_brick(lists, brick + step);
    if (out.next[a] == nb) continue;
    Coord last{0, 0, 0};
    last[a] = kBrickDim - 1;
    out.step[a] = rel[std::size_t(local_index(last.x, last.y, last.z))] +
                  edge_jump(grid, ids(i), ids(out.next[a]), brick_origin(brick) + last, a);
  }
  return out;
}

// The masks, or nothing when the rays would cost more than the tree (many separate groups of
// bricks) or the links disagree (never for a closed mesh: kept as a guard).
std::optional<std::vector<BrickMask>> closed_masks(std::span<const GridTriangle> grid,
                                                   const BrickTriangleLists& lists,
                                                   const InsideMasksOptions& options,
                                                   std::uint64_t& rays) {
  const std::size_t nb = lists.bricks.size();
  std::vector<RelativeBrick> bricks(nb);
  for (std::size_t start = 0; start < nb; start += kBatchBricks) {
    const std::size_t end = std::min(nb, start + kBatchBricks);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(start, end, 4),
                      [&](const tbb::blocked_range<std::size_t>& range) {
      options.progress.check("sign");
      BrickCrossings scratch;
      for (std::size_t i = range.begin(); i != range.end(); ++i)
        bricks[i] = relative_brick(grid, lists, i, scratch);
    });
    options.progress.step(0.9 * double(end) / double(nb), "sign");
  }
  // Face-connected groups, each base relative to its group's first brick. The -axis
  // neighbours are the +axis links read backwards.
  std::vector<std::array<std::size_t, 3>> prev(nb, {nb, nb, nb});
  for (std::size_t i = 0; i < nb; ++i)
    for (int a = 0; a < 3; ++a)
      if (bricks[i].next[a] != nb) prev[bricks[i].next[a]][a] = i;
  constexpr std::size_t kNone = ~std::size_t{0};
  std::vector<std::size_t> group(nb, kNone);
  std::vector<int> base(nb, 0);
  std::vector<std::size_t> roots, queue;
  for (std::size_t r = 0; r < nb; ++r) {
    if (group[r] != kNone) continue;
    group[r] = roots.size();
    roots.push_back(r);
    queue.assign(1, r);
    while (!queue.empty()) {
      const std::size_t i = queue.back();
      queue.pop_back();
      for (int a = 0; a < 6; ++a) {
        const std::size_t j = a < 3 ? bricks[i].next[a] : prev[i][a - 3];
        if (j == nb) continue;
        const int change = a < 3 ? bricks[i].step[a] : -bricks[j].step[a - 3];
        if (group[j] != kNone) {
          if (base[j] != base[i] + change) return std::nullopt;
          continue;
        }
        group[j] = group[i];
        base[j] = base[i] + change;
        queue.push_back(j);
      }
    }
  }
  if (double(roots.size()) * double(grid.size()) > options.max_ray_work) return std::nullopt;
  std::vector<int> anchor(roots.size());
  tbb::parallel_for(std::size_t(0), roots.size(), [&](std::size_t g) {
    anchor[g] = ray_winding(grid, brick_origin(lists.bricks[roots[g]]));
  });
  rays = roots.size();
  std::vector<BrickMask> inside(nb);
  tbb::parallel_for(std::size_t(0), nb, [&](std::size_t i) {
    // Inside: w = w(base) + rel >= 1, i.e. rel >= 1 - w(base).
    const int need = 1 - (anchor[group[i]] + base[i]);
    const RelativeBrick& b = bricks[i];
    if (!b.rel.empty()) {
      for (int n = 0; n < kBrickVoxels; ++n)
        if (b.rel[std::size_t(n)] >= need) inside[i].set(n);
    } else if (need <= b.lo)
      inside[i].words.fill(~std::uint64_t{0});
    else if (need - b.lo <= int(b.levels.size()))
      inside[i] = b.levels[std::size_t(need - b.lo - 1)];
  });
  return inside;
}

}  // namespace

InsideMasksResult compute_inside_masks(const TriangleMesh& oriented_mesh,
                                       const WindingNumberTree& tree,
                                       const BrickTriangleLists& lists,
                                       const InsideMasksOptions& options) {
  return compute_inside_masks(oriented_mesh, LazyWindingTree(tree), lists, options);
}

InsideMasksResult compute_inside_masks(const TriangleMesh& oriented_mesh,
                                       const LazyWindingTree& tree,
                                       const BrickTriangleLists& lists,
                                       const InsideMasksOptions& options) {
  if (lists.offsets.empty() && lists.bricks.empty()) return {};
  validate(oriented_mesh, tree, lists, options);
  const GridFrame& frame = options.frame;
  const std::vector<Vec3d> grid_vertices = to_grid_vertices(oriented_mesh, frame);
  const std::vector<GridTriangle> grid = to_grid_triangles(oriented_mesh, grid_vertices);
  InsideMasksResult result;
  const OpenEdgeInfo open = find_open_edges(oriented_mesh, grid_vertices, grid, lists);
  result.open_edges = open.count;
  const std::size_t nb = lists.bricks.size();
  // The jumps across brick faces need every triangle crossing such an edge listed in one of
  // the two bricks: a margin of half a voxel.
  if (open.count == 0 && options.closed_by_rays && lists.margin >= 0.5 * frame.voxel_size) {
    if (auto inside = closed_masks(grid, lists, options, result.ray_queries)) {
      result.inside = std::move(*inside);
      options.progress.step(1.0, "sign");
      return result;
    }
  }
  (void)tree.get();  // built here, before the parallel loop (see LazyWindingTree)
  const std::vector<bool>& unsafe = open.near_brick;
  result.inside.resize(nb);
  const BrickWindingContext context{tree, frame, options.beta};
  std::vector<std::uint64_t> queries(nb, 0);
  for (std::size_t start = 0; start < nb; start += kBatchBricks) {
    const std::size_t end = std::min(nb, start + kBatchBricks);
    tbb::parallel_for(
        tbb::blocked_range<std::size_t>(start, end, 4),
        [&](const tbb::blocked_range<std::size_t>& range) {
          options.progress.check("sign");
          BrickCrossings crossings;
          std::vector<OpenSegment> rims;
          std::vector<std::uint64_t> scratch;
          for (std::size_t i = range.begin(); i != range.end(); ++i) {
            const std::span<const std::uint32_t> ids(lists.triangles.data() + lists.offsets[i],
                                                     lists.offsets[i + 1] - lists.offsets[i]);
            if (unsafe[i]) {
              crossings = BrickCrossings{};
              brick_crossings(grid, ids, lists.bricks[i], kAllLines, crossings);
              gather_rims(lists, i, grid, open, frame.voxel_size, scratch, rims);
              result.inside[i] =
                  inside_adaptive(crossings, lists.bricks[i], rims, context, queries[i]);
            } else {
              result.inside[i] =
                  inside_from_reference(grid, ids, lists.bricks[i], context, crossings, queries[i]);
            }
          }
        });
    options.progress.step(double(end) / double(nb), "sign");
  }
  for (std::size_t i = 0; i < nb; ++i) {
    result.winding_queries += queries[i];
    result.direct_bricks += unsafe[i];
  }
  return result;
}

}  // namespace levelset
