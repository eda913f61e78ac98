// Signed crossings of triangles with the grid edges of one brick: the integer jumps of the
// winding number between adjacent voxel centres, computed watertight.
//
// Grid space: a voxel (i, j, k) sits at origin + h (i, j, k); to_grid_vertices maps every
// vertex once to (v - origin) / h, so shared vertices stay bit-identical.
// Convention (symbolic perturbation, Edelsbrunner-Muecke "simulation of simplicity"): every
// voxel centre p is treated as p - (e1, e2, e3) with infinitesimals e1 >> e2 >> e3 > 0. No
// perturbed centre lies on a triangle's plane and no perturbed grid line meets a triangle's
// edge, so every test below has a definite answer, computed exactly (exact_predicates.hpp):
//   - the line along axis w through a brick's (u, v) voxel column hits triangle t when the
//     perturbed point lies inside t's projection (t's normal component n_w != 0; triangles
//     parallel to w never cross a perturbed line);
//   - it crosses grid edge [m, m+1) when perturbed centres m and m+1 lie on opposite sides of
//     t's plane.
// A crossing changes the winding number by -sign(n_w) from m to m+1 (entering the solid
// through an outward face adds 1). For a closed mesh (every edge's uses cancel) the sum of
// crossings along any closed grid path is exactly zero, so accumulated winding numbers are path
// independent and equal the winding number of the perturbed centres; a point exactly on the
// surface is classified like the point displaced by -x first, then -y, then -z (for an
// axis-aligned box [x0, x1] x ... its voxels with x0 < i <= x1, ... are inside).
//
// brick_crossings
//   Inputs: grid triangles, the indices of those that meet the brick's voxel-centre box (more
//   are harmless), the brick coordinates, the grid lines wanted. Output (added, per selected
//   line; others untouched): delta[w][line][e] = winding change from local
//   voxel e to e + 1 (e in 0..6) along axis w on the line with local coordinates
//   (l_u, l_v) = line & 7, line >> 3 where u = (w + 1) % 3, v = (w + 2) % 3; near = voxels at an
//   end of a crossed edge (also where crossings cancel); on_surface = voxels exactly on a
//   triangle whose projection holds the perturbed line through them (for a watertight surface:
//   every voxel exactly on it).
//   Cost: per triangle and axis, one 2D test per grid line of the brick inside the projected
//   bounding box (~20 flops, filtered) and ~4 plane-side tests per hit.
//   Threading: pure; call concurrently for different bricks. Errors: none.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "core/vec3.hpp"
#include "grid/brick_mask.hpp"
#include "grid/coord.hpp"
#include "grid/narrow_band.hpp"
#include "io/triangle_mesh.hpp"

namespace levelset {

struct GridTriangle {
  std::array<Vec3d, 3> corner;             // grid space
  std::array<std::int8_t, 3> normal_sign;  // exact sign of ((b - a) x (c - a))[axis]
};

// Grid-space vertices (v - origin) / h, and grid-space copies of all triangles with the exact
// signs of their normals (TBB parallel; indices must be valid); make_grid_triangle: one.
std::vector<Vec3d> to_grid_vertices(const TriangleMesh& mesh, const GridFrame& frame);
GridTriangle make_grid_triangle(const Vec3d& a, const Vec3d& b, const Vec3d& c);
std::vector<GridTriangle> to_grid_triangles(const TriangleMesh& mesh,
                                            std::span<const Vec3d> grid_vertices);

struct BrickCrossings {
  std::array<std::array<std::array<std::int32_t, 8>, 64>, 3> delta{};  // [axis][line][edge]
  BrickMask near;        // voxels at an end of a crossed edge
  BrickMask on_surface;  // voxels found exactly on a triangle (a subset of near)
};

// Per axis w, bit l_u + 8 l_v selects the grid line (l_u, l_v) of the brick.
using LineSet = std::array<std::uint64_t, 3>;
inline constexpr LineSet kAllLines{~0ull, ~0ull, ~0ull};

// Adds the crossings on the selected lines to `out` (start from BrickCrossings{}).
void brick_crossings(std::span<const GridTriangle> triangles, std::span<const std::uint32_t> ids,
                     const Coord& brick, const LineSet& lines, BrickCrossings& out);

// The winding jump from global voxel `voxel` to voxel + e_w (the same value brick_crossings
// gives that edge), over the triangles in ids_a and ids_b (each sorted; their union is used,
// so the lists of the two bricks the edge joins hold every triangle crossing it when their
// margin is at least half a voxel). Cost: O(|ids_a| + |ids_b|) box tests.
int edge_jump(std::span<const GridTriangle> triangles, std::span<const std::uint32_t> ids_a,
              std::span<const std::uint32_t> ids_b, const Coord& voxel, int w);

// The exact winding number of the perturbed voxel centre for a closed mesh (every edge's uses
// cancel): the signed crossings of all triangles with the ray from it along +x (w = 0 beyond
// the mesh). Cost: O(triangles) box tests. Threading: pure.
int ray_winding(std::span<const GridTriangle> triangles, const Coord& voxel);

}  // namespace levelset
