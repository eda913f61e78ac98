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
// Method: (thesis 2.3.4, 4.5; Mauch's CPT, which the thesis's CPT library used) every voxel
//   gets the minimum exact point-triangle distance over the triangles whose characteristic
//   polyhedra contain it: the prism of each face, the wedge of each edge, the cone of each
//   vertex, scan-converted column by column (characteristic_scan.hpp); about one to two
//   evaluations per band voxel on smooth meshes, whatever W and the triangle density. The slab
//   scan instead bins triangles to the bricks they come within W*h of and scan-converts each
//   triangle's slab (|plane distance| <= W*h) per brick: the same values (the tests compare
//   them on every CGAL mesh), W^3 work per triangle, cheaper only for narrow bands around
//   coarse meshes (options.method chooses; automatic by a cost estimate). Ties: lowest
//   triangle index. No per-voxel loop over all triangles. Sign: faces are oriented
//   consistently (orient_faces), then every voxel of every brick gets the generalized winding
//   number test (> 1/2 is inside) from signed crossings along grid edges plus, for closed
//   meshes, one exact ray per connected group of bricks, otherwise one hierarchical
//   evaluation per brick, more near open edges, whose nearby segments' cones carry the
//   continuous part (compute_inside_masks, brick_winding.hpp) — robust for holes, open boundaries,
//   self-intersections and flipped faces (thesis open issue 5.3). Then, for open meshes only,
//   the membranes (membrane_band.hpp).
// Cost: characteristic: O(band voxels + triangles * columns per polyhedron); slab scan:
//   O(triangles * (triangle size + 2W)^2 * 2W).
// Threading: TBB over triangles and bricks; identical results for any thread count.
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

enum class CptMethod {
  automatic,       // the characteristic scan, or the slab scan where it is estimated cheaper
  slab_scan,       // every triangle's slab within W*h (thesis 2.3.4): W^3 work per triangle
  characteristic,  // characteristic polyhedra (characteristic_scan.hpp): O(band voxels)
};

struct CptOptions {
  GridFrame frame;
  bool closest_points = false;
  CptMethod method = CptMethod::automatic;
  // Voxel budget: the mesh's bounding box padded by the band, in voxels.
  std::uint64_t max_domain_voxels = std::uint64_t{1} << 36;
  ProgressHook progress;
};

struct CptTimings {
  double orient = 0, bin = 0, distance = 0, sign = 0, membrane = 0, assemble = 0, total = 0;
};

struct CptResult {
  NarrowBand band;
  std::vector<Vec3f> closest_points;  // per active voxel, in band value order (if requested)
  std::uint64_t triangles = 0;
  CptMethod method = CptMethod::slab_scan;  // as used (options.method or chosen)
  std::uint64_t brick_triangle_pairs = 0;   // triangles listed per brick (within W*h or 1 voxel)
  std::uint64_t polyhedra = 0;              // characteristic polyhedra scanned
  std::uint64_t evaluations = 0;            // ... and their point-triangle distances
  std::uint64_t faces_flipped = 0;  // by the orientation pass
  std::uint64_t winding_queries = 0;  // tree evaluations (open meshes)
  std::uint64_t ray_queries = 0;      // exact ray winding numbers (closed meshes)
  std::uint64_t open_edges = 0;                 // of the oriented sign mesh (0: closed)
  std::uint64_t membrane_voxels = 0;            // ends of sign changes across holes
  std::uint64_t membrane_bricks_added = 0;      // bricks beyond the mesh's band
  std::uint64_t membrane_voxels_added = 0;      // active voxels beyond the mesh's band
  std::uint64_t membrane_truncated_bricks = 0;  // membrane left open there (see membrane_band)
  CptTimings seconds;
};

CptResult closest_point_transform(const TriangleMesh& mesh, const CptOptions& options);

}  // namespace levelset
