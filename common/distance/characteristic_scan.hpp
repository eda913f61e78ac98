// characteristic_scan: exact unsigned distances and closest triangles over a narrow band by
// scan conversion of characteristic polyhedra (Mauch's CPT, the thesis's CPT library).
//
// Inputs: a triangle mesh (world units; any soup: open, non-manifold, degenerate faces), the
//   bricks of a thin shell around it (bin_triangles_to_bricks with a margin >= the voxel's
//   half-diagonal: every brick within sqrt(3)/2 h of a triangle), options.frame (h, origin,
//   band half-width W voxels).
// Output: a ClosestTriangleField over every brick within ceil((W + 1) / 8) bricks of a shell
//   brick: at every voxel within W*h of the mesh the exact distance (float of the double
//   closest_point_on_triangle value) and a closest triangle; +inf / kNoTriangle elsewhere.
// Method: a voxel whose closest point lies inside face T lies in T's prism (the points that
//   project into T, within W*h of its plane); one whose closest point lies inside edge e lies
//   in e's wedge (beyond e as seen from each face at e, between its end planes); one whose
//   closest point is vertex v lies in v's cone (every edge at v points away from it). Each
//   polyhedron is a convex set of half-spaces, a superset of the feature's Voronoi cell, widened
//   by 1e-7 h against rounding; it is scan-converted column by column (its box, the interval
//   of each column from its half-spaces) and each voxel inside takes the exact distance to the
//   triangle the feature belongs to, keeping the minimum (ties: lowest triangle index). Faces
//   and edges of every triangle, vertices once (by their lowest-index triangle); vertices are
//   welded by exact position. So every voxel is evaluated against its true closest triangle:
//   exact, with about one to two evaluations per band voxel on smooth meshes. Shortcuts that
//   keep this: an edge's wedge thinner than 1/4 voxel at the band's edge (nearly coplanar
//   faces) is covered by the face's prism with its edge planes moved out by that much; a
//   vertex whose ring lies in its face's plane, or whose cone is the vertex alone (a saddle),
//   scans nothing; a degenerate face whose vertices lie on one line scans its longest edge's
//   cylinder, less the parts that lower-numbered collinear faces scan (collinear_segments.hpp:
//   subdivided degenerate faces overlap many times over on their line); a voxel whose distance
//   to a triangle's plane (less a rounding margin) exceeds its best distance so far is not
//   evaluated against that triangle. The polyhedra's scan conversion: polyhedron_scan.hpp.
// Cost: O(triangles * columns per polyhedron + band voxels * polyhedra per voxel); memory 8
//   bytes per voxel of the dilated bricks. Threading: TBB over triangles (atomic minimum per
//   voxel, order independent): identical results for any thread count.
// Errors: Error{Cancelled} via the progress hook.
#pragma once

#include <cstdint>
#include <vector>

#include "core/progress.hpp"
#include "core/uninitialized_vector.hpp"
#include "grid/narrow_band.hpp"
#include "io/triangle_mesh.hpp"

namespace levelset {

inline constexpr std::uint32_t kNoTriangle = 0xffffffffu;

// Per-voxel unsigned distance and closest triangle over a sorted set of bricks.
struct ClosestTriangleField {
  std::vector<Coord> bricks;         // sorted by brick_key
  UninitializedVector<float> distance;       // bricks.size() * kBrickVoxels; +inf: not in the band
  UninitializedVector<std::uint32_t> owner;  // closest triangle per voxel, or kNoTriangle
};

struct CharacteristicScanOptions {
  GridFrame frame;
  ProgressHook progress;
};

struct CharacteristicScanResult {
  ClosestTriangleField field;
  std::uint64_t polyhedra = 0;     // prisms, wedges and cones scanned
  std::uint64_t evaluations = 0;   // point-triangle distances evaluated
  std::uint64_t odd_edges = 0;  // welded edges used by an odd number of triangles (borders)
};

CharacteristicScanResult characteristic_scan(const TriangleMesh& mesh, const std::vector<Coord>& shell_bricks,
                                             const CharacteristicScanOptions& options);

}  // namespace levelset
