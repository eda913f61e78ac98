#include "distance/inside_masks.hpp"

#include <algorithm>
#include <array>
#include <cmath>
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

// Open edges (open_edges.hpp) per triangle, and the bricks near them: those listing a triangle
// with an open edge, and the listed bricks within kOpenReach bricks of those (reach >= 16
// voxels; beyond it the continuous part of w changes by well under 1/2 across a brick).
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
  for (std::size_t i = 0; i < nb; ++i) {
    bool core = false;
    for (std::uint64_t k = lists.offsets[i]; k < lists.offsets[i + 1] && !core; ++k)
      core = info.triangle_edges[lists.triangles[k]] != 0;
    if (!core) continue;
    for (int dz = -kOpenReach; dz <= kOpenReach; ++dz)
      for (int dy = -kOpenReach; dy <= kOpenReach; ++dy)
        for (int dx = -kOpenReach; dx <= kOpenReach; ++dx) {
          const std::size_t j = find_brick(lists, lists.bricks[i] + Coord{dx, dy, dz});
          if (j < nb) info.near_brick[j] = true;
        }
  }
  return info;
}

// The open edges of the triangles listed by a brick and its 26 neighbours (every open edge
// within the brick's width of it, given a margin >= 0), in brick-local grid coordinates.
void gather_rims(const BrickTriangleLists& lists, std::size_t i, std::span<const GridTriangle> grid,
                 const OpenEdgeInfo& info, std::vector<std::uint64_t>& scratch,
                 std::vector<OpenSegment>& rims) {
  rims.clear();
  scratch.clear();
  for (int dz = -1; dz <= 1; ++dz)
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
        const std::size_t j = find_brick(lists, lists.bricks[i] + Coord{dx, dy, dz});
        if (j == lists.bricks.size()) continue;
        for (std::uint64_t k = lists.offsets[j]; k < lists.offsets[j + 1]; ++k) {
          const std::uint32_t t = lists.triangles[k];
          for (int e = 0; e < 3; ++e)
            if ((info.triangle_edges[t] >> e) & 1u)
              scratch.push_back(std::uint64_t(t) * 4 + std::uint64_t(e));
        }
      }
  std::sort(scratch.begin(), scratch.end());
  scratch.erase(std::unique(scratch.begin(), scratch.end()), scratch.end());
  const Coord o = brick_origin(lists.bricks[i]);
  const Vec3d origin{double(o.x), double(o.y), double(o.z)};
  for (std::uint64_t code : scratch) {
    const GridTriangle& g = grid[code / 4];
    const int e = int(code % 4);
    rims.push_back({g.corner[e] - origin, g.corner[(e + 1) % 3] - origin});
  }
}

void validate(const TriangleMesh& mesh, const WindingNumberTree& tree,
              const BrickTriangleLists& lists, const InsideMasksOptions& options) {
  const GridFrame& f = options.frame;
  if (!(std::isfinite(f.voxel_size) && f.voxel_size > 0.0) || !isfinite(f.origin))
    throw Error(ErrorCode::InvalidArgument, "frame",
                "voxel size must be finite and > 0, origin finite");
  if (!(options.beta > 0.0) || !std::isfinite(options.beta))
    throw Error(ErrorCode::InvalidArgument, "beta", "must be finite and > 0");
  const std::size_t nt = mesh.triangles.size();
  validate_mesh(mesh);
  if (tree.order.size() != nt)
    throw Error(ErrorCode::InvalidArgument, "winding tree",
                "built from a mesh with " + std::to_string(tree.order.size()) + " triangles, not " +
                    std::to_string(nt));
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

}  // namespace

InsideMasksResult compute_inside_masks(const TriangleMesh& oriented_mesh,
                                       const WindingNumberTree& tree,
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
  const std::vector<bool>& unsafe = open.near_brick;
  const std::size_t nb = lists.bricks.size();
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
              gather_rims(lists, i, grid, open, scratch, rims);
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
