// closest_point_transform: exact signed distance from a triangle mesh on a narrow band.
//
// Inputs: a triangle mesh (world units; any soup: open, non-manifold, self-intersecting,
//   inconsistently oriented, with degenerate faces), options.frame (voxel size h, origin,
//   band half-width W voxels).
// Output: a NarrowBand holding, at every voxel within W*h of the mesh, the exact Euclidean
//   distance to the closest point of the mesh, negative inside; and on request the closest
//   point itself per active voxel (in band value order), for the client's 'vector to closest
//   point' display and for extension velocities. The sign is the inside mask's at every voxel,
//   also exactly on the surface (compute_inside_masks' convention): an inside voxel at
//   distance 0 holds -FLT_MIN, never -0, so value < 0 is exactly the winding-number inside.
//   Open meshes (open edges: holes, borders, inconsistent regions): the sign also changes where
//   w crosses 1/2 away from the mesh, across each hole (its membrane); those voxels and all
//   within W*h of them are in the band too, valued sign * min(distance to the mesh, distance
//   to the membrane) (close_membranes, membrane_band.hpp), so the zero level is closed and the
//   band invariant holds; closest points there are the nearest membrane points (estimated).
//   Closed meshes are untouched by this (bit for bit).
// Method: (thesis 2.3.4, 4.5) triangles are binned to the bricks they come within the exact
//   shell (options.exact_shell voxels, at most W) of; each brick scan-converts its triangles'
//   slabs (|plane distance| <= shell, per column of the dominant axis) and keeps the minimum
//   exact point-triangle distance per voxel (ties: lowest triangle index). No per-voxel loop
//   over all triangles. With a shell thinner than W, the rest of the band gets its closest
//   triangle by propagation from the shell in distance order (candidates from the neighbours,
//   exact evaluation, a descent over the triangles around the best one:
//   closest_triangle_propagation.hpp), whose work per voxel does not grow with W or the
//   triangle density. Sign: faces are oriented
//   consistently (orient_faces), then every voxel of every brick gets the generalized winding
//   number test (> 1/2 is inside) from one hierarchical evaluation per brick plus signed
//   crossings along grid edges (compute_inside_masks) — robust for holes, open boundaries,
//   self-intersections and flipped faces (thesis open issue 5.3). Then, for open meshes only,
//   the membranes (membrane_band.hpp).
// Cost: O(triangles * slab voxels per triangle) for the scan (the slab is the shell's: ~W^3 per
//   triangle by default), plus O(band voxels * (26 + candidates)) for the propagation.
// Threading: TBB over triangles and bricks; bit-identical results for any thread count.
// Errors: Error{InvalidArgument} for an empty mesh or bad indices, Error{NonFinite} for NaN or
//   Inf vertices, Error{LimitExceeded} when the mesh needs more than options.max_domain_voxels
//   (the voxel budget) or leaves the index range; Error{Cancelled} via the progress hook.
#pragma once

#include <cstdint>
#include <vector>

#include "core/progress.hpp"
#include "grid/narrow_band.hpp"
#include "io/triangle_mesh.hpp"

namespace levelset {

struct CptOptions {
  GridFrame frame;
  bool closest_points = false;
  // Voxels: distances up to this far from the mesh come from the slab scan, the rest of the
  // band from closest-triangle propagation (closest_triangle_propagation.hpp) then, when
  // `exact`, a nearest-triangle query per propagated voxel bounded by its propagated distance
  // (exact: the same values as the scan). A value >= W scans the whole band. Negative (the
  // default): 1 or W, whichever the costs estimated from the mesh favour (the scan on coarse
  // meshes and narrow bands; propagation on dense meshes with wide bands, measured 1.8x
  // faster on a 588k-triangle sphere at W = 12). Both choices give the same values.
  double exact_shell = -1.0;
  // false: propagation only, 1.5-3x faster beyond the shell but not exact there (measured on
  // CGAL's closed meshes at W = 6: up to 0.15 h too far on 0.5 % of those voxels; smooth
  // meshes: none), and a voxel near the band's rim can be missed (test_cpt_propagation).
  bool exact = true;
  // Voxel budget: the mesh's bounding box padded by the band, in voxels.
  std::uint64_t max_domain_voxels = std::uint64_t{1} << 36;
  ProgressHook progress;
};

struct CptTimings {
  double orient = 0, bin = 0, distance = 0, propagate = 0, sign = 0, membrane = 0, assemble = 0, total = 0;
};

struct CptResult {
  NarrowBand band;
  std::vector<Vec3f> closest_points;  // per active voxel, in band value order (if requested)
  std::uint64_t triangles = 0;
  double exact_shell = 0;                   // voxels, as used (options.exact_shell or chosen)
  std::uint64_t brick_triangle_pairs = 0;   // within the exact shell
  std::uint64_t propagation_layers = 0;     // distance buckets beyond the shell
  std::uint64_t propagation_evaluations = 0;  // point-triangle distances they evaluated
  std::uint64_t propagation_corrected = 0;    // propagated voxels the exact pass corrected
  std::uint64_t faces_flipped = 0;  // by the orientation pass
  std::uint64_t winding_queries = 0;
  std::uint64_t open_edges = 0;                 // of the oriented sign mesh (0: closed)
  std::uint64_t membrane_voxels = 0;            // ends of sign changes across holes
  std::uint64_t membrane_bricks_added = 0;      // bricks beyond the mesh's band
  std::uint64_t membrane_voxels_added = 0;      // active voxels beyond the mesh's band
  std::uint64_t membrane_truncated_bricks = 0;  // membrane left open there (see membrane_band)
  CptTimings seconds;
};

CptResult closest_point_transform(const TriangleMesh& mesh, const CptOptions& options);

}  // namespace levelset
