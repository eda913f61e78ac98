// TriangleBvh: a bounding-volume hierarchy over a triangle mesh for exact nearest-triangle
// queries with a starting bound.
//
// Inputs: a triangle mesh (world units, double precision; degenerate faces allowed). The tree
//   keeps its own copy of the vertex positions in leaf order, so the mesh may go away.
// Query: nearest(p, bound2) -> the triangle nearest to p among those strictly nearer than
//   sqrt(bound2) (ties: the first met), its squared distance, or tri = kNoBvhTriangle when none
//   is. Exact: boxes are the exact min / max of their triangles' vertices, distances come from
//   closest_point_on_triangle, and a box is skipped only when its distance is >= the best so
//   far. A tight bound (a propagated closest triangle's distance) makes a query visit only the
//   few boxes that reach into the ball of that radius.
// Cost: build O(F log F) (parallel over the top levels), 112 bytes per triangle; a query
//   O(log F + boxes reaching the bound's ball). Thread-safe queries.
// Errors: none (an empty mesh gives an empty tree whose queries find nothing).
#pragma once

#include <cstdint>
#include <vector>

#include "core/vec3.hpp"
#include "io/triangle_mesh.hpp"

namespace levelset {

inline constexpr std::uint32_t kNoBvhTriangle = 0xffffffffu;

struct BvhHit {
  double distance_squared;
  std::uint32_t tri = kNoBvhTriangle;  // index in the mesh
};

class TriangleBvh {
 public:
  explicit TriangleBvh(const TriangleMesh& mesh);
  BvhHit nearest(const Vec3d& p, double bound2) const;
  std::size_t node_count() const { return nodes_.size(); }

 private:
  struct Node {
    Vec3d lo, hi;
    std::uint32_t first = 0;  // leaf: first slot; inner: left child (node + 1)
    std::uint32_t count = 0;  // leaf: triangles; 0 for inner nodes
    std::uint32_t right = 0;  // inner: right child
  };
  struct Leaf {
    Vec3d a, b, c;
    std::uint32_t tri;
  };
  void build(std::uint32_t node, std::uint32_t begin, std::uint32_t end, std::vector<Vec3d>& centroids,
             int depth);
  std::vector<Node> nodes_;
  std::vector<Leaf> leaves_;  // triangles in leaf order
};

}  // namespace levelset
