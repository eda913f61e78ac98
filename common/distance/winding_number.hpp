// Generalized winding numbers of triangle soups, fast (after Barill, Dickson, Schmidt, Levin,
// Jacobson, "Fast Winding Numbers for Soups and Clouds", SIGGRAPH 2018).
//
// w(p) = (1 / 4 pi) * sum over triangles of the signed solid angle seen from p (solid_angle.hpp).
// For a closed, outward-oriented mesh w is 1 inside and 0 outside; for open, holed,
// self-intersecting or multiply-covered meshes it varies smoothly away from the surface and
// jumps by the local covering number across it, so w > 1/2 is a robust inside test.
//
// build_winding_tree
//   Input: a mesh (world units). Output: a bounding-volume hierarchy over its triangles (median
//   splits along the longest axis of the centroid box, leaves of at most kLeafTriangles). Every
//   node stores the area-weighted centroid c of its triangles, the radius of the ball about c
//   holding all their vertices, and the Taylor coefficients of their solid-angle field about c
//   up to second order: the area-weighted normal sum N (dipole), the first moment
//   M = sum a n (x - c)^T and the second moment C = sum a n (x - c)(x - c)^T, both integrated
//   over the triangles (their own extent included).
//   Cost: O(F log F) time, ~0.45 KB per leaf (two nodes) plus 72 bytes per triangle; the
//   build's moments (~0.5 KB per leaf) are freed after it. Threading: TBB
//   (parallel recursion); the tree is identical for any thread count.
//   Errors: Error{InvalidArgument} for vertex indices out of range, Error{NonFinite} for
//   non-finite vertices.
// winding_number(tree, p, beta)
//   Descends a node only when |p - c| > beta * radius fails, otherwise uses its expansion
//   (error ~ beta^-3 of the node's solid angle); leaves reached are summed exactly (up to the
//   polynomial arctangent's 4e-8 sr per triangle, solid_angle.hpp). Measured
//   worst |w - exact| over random points near and far from CGAL's knot.off and bunny00.off:
//   beta = 2: 5e-3 (the default: ~3 us per query near 75k triangles), beta = 3: 8e-4,
//   beta = 4: 3e-4 (~14 us). Cost O(log F) nodes away from the surface, more near it.
//   Threading: const, safe to call concurrently. Errors: none.
// winding_numbers(tree, points, beta, out)
//   winding_number for each of a batch of points (out[i] for points[i]) in one
//   traversal: the points that reach a node and are far from it take its expansion, the others
//   descend together. Bit-identical to the single queries; the nodes' loads and the traversal
//   are shared, which pays for clustered points (a brick's).
// LazyWindingTree
//   A tree that is built on first use (get(), thread-safe: one build, concurrent callers wait),
//   or one the caller already has. The sign code needs it only for open meshes and as a
//   fallback, so closed meshes never pay for the build. The mesh must outlive it. The build
//   runs in an isolated TBB region: while it waits for its own parallel parts, the building
//   thread does not pick up outer tasks that could call get() again (a recursive call_once).
//   Callers that know they need the tree call get() before their parallel loops.
// winding_number_exact(mesh, p)
//   The brute-force sum over all triangles (reference for tests), O(F). Indices must be valid.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <mutex>
#include <optional>
#include <span>
#include <vector>

#include "core/vec3.hpp"
#include "io/triangle_mesh.hpp"

namespace levelset {

struct WindingNumberTree {
  static constexpr int kLeafTriangles = 8;
  struct Node {               // what the traversal reads for every node it visits
    Vec3d center;             // area-weighted centroid of the node's triangles
    double radius = 0.0;      // all vertices lie within this distance of center
    std::uint32_t left = 0;   // inner node: children left, right; leaf: triangles
    std::uint32_t right = 0;  // [left, right) in corners
    bool leaf = false;
  };
  // The node's expansion (its moments N, M, C about center, see above) as a polynomial in
  // y = center - p, what the traversal reads for nodes it approximates: solid angle
  // = (q1 + (q3 / r^2 - q2) / r^2) / r^3 with q1 = N.y + tr M, q2 = 3 y^T M y + 3/2 l.y and
  // q3 = 15/2 sum_i y_i y^T C_i y (23 numbers instead of the moments' 30).
  struct FarField {
    Vec3d normal;                   // N
    double trace = 0.0;             // tr M
    std::array<double, 6> quad{};   // q2's coefficients of xx, yy, zz, xy, xz, yz
    Vec3d lin;                      // 3/2 l, l_k = 2 sum_i (C_i)_ik + tr C_k
    std::array<double, 10> cubic{}; // q3's coefficients of x^3, y^3, z^3, x^2 y, x^2 z, y^2 x, y^2 z,
                                    // z^2 x, z^2 y, x y z
  };
  std::vector<Node> nodes;                    // nodes[0] is the root (empty mesh: no nodes)
  std::vector<FarField> far;                  // per node
  std::vector<std::array<Vec3d, 3>> corners;  // triangle vertices in leaf order
  std::vector<std::uint32_t> order;           // mesh triangle index of corners[i]
};

WindingNumberTree build_winding_tree(const TriangleMesh& mesh);

double winding_number(const WindingNumberTree& tree, const Vec3d& p, double beta = 2.0);
void winding_numbers(const WindingNumberTree& tree, std::span<const Vec3d> points, double beta,
                     std::span<double> out);

class LazyWindingTree {
 public:
  explicit LazyWindingTree(const TriangleMesh& mesh) : mesh_(&mesh) {}
  explicit LazyWindingTree(const WindingNumberTree& tree) : given_(&tree) {}
  const WindingNumberTree& get() const;
  // The tree the caller gave (nullptr when it is built here).
  const WindingNumberTree* given() const { return given_; }
  bool built() const { return given_ != nullptr || owned_.has_value(); }

 private:
  const TriangleMesh* mesh_ = nullptr;
  const WindingNumberTree* given_ = nullptr;
  mutable std::once_flag once_;
  mutable std::optional<WindingNumberTree> owned_;
};

double winding_number_exact(const TriangleMesh& mesh, const Vec3d& p);

}  // namespace levelset
