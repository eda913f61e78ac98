// Winding numbers of the 512 voxels of one brick from a few tree queries plus the exact jumps
// between adjacent voxels (grid_crossings.hpp). Used by compute_inside_masks.
//
// inside_from_reference
//   For bricks away from open edges, where the winding number is constant apart from its
//   integer jumps across the surface. One query at a reference voxel: the interior voxel
//   nearest the brick centre that is farthest (up to two voxels) from any crossed edge, and
//   not next to a crossing itself; every voxel then gets w_ref plus the jumps along the path
//   reference -> along x -> along y -> along z. Only the lines of that path are computed (all
//   64 along z, the reference's x-row and the 8 y-lines of its z-slice). For a closed mesh the
//   result is path independent and exact up to the tree's error in w_ref (far below 1/2).
// inside_adaptive
//   For bricks near open edges, where w also varies continuously (the field of the open edges,
//   Biot-Savart-like, strong only close to them). Recursive octree refinement of the brick
//   (8^3, 4^3 blocks): w = w(ref) + the jumps along the path from ref + the trilinear
//   interpolation of the corners' residuals, accepted when a direct query at the block centre
//   agrees within kAdaptiveTolerance; otherwise the block splits into octants (each reusing
//   the corner inside it), and 2^3 blocks are queried voxel by voxel.
//   - A block with no open edge within half its size (rims: the open edges near the brick, in
//     brick-local grid coordinates) has path-independent jumps, and the rest of w is smooth in
//     it.
//   - A block with open edges that near first subtracts their cone's winding number w_C,
//     exact per voxel (rim_cone.hpp): w - w_C has path-independent jumps (those of the surface
//     and of the reversed cone) and is smooth there. Its voxels modelled within 0.02 of 1/2
//     are queried directly. Before the cones, every voxel within ~2 voxels of an open edge was
//     queried: CGAL's elephant-with-holes subdivided to 17852 triangles at R = 128, 152k ->
//     9.7k queries, 0.44 -> 0.07 s (2 threads); fewer voxels disagree with the exact winding
//     number than with those direct queries (b9_mesh: 485 -> 422 of 367k voxels, all within
//     0.1 of 1/2).
//   Voxels exactly on the surface are never queried (their direct value is the mean of the two
//   sides); they take a neighbour's value plus the exact jump, following the perturbation
//   convention. Cost: 9 queries per brick where the field is smooth, more near open edges.
// Output of both: bit n set when w > 1/2; queries counts the tree evaluations made.
// relative_winding
//   For closed meshes (every edge's uses cancel), with no query: every voxel's winding number
//   minus that of the brick's base voxel (local 0, 0, 0), summing the jumps along the path
//   base -> along x -> along y -> along z (the base's x-line, the y-lines of its z-slice, all
//   64 z-lines). Exact (path independent for closed meshes); rel[local_index(7 e_a)] is the
//   change along the base's line on axis a.
// Threading: pure; call concurrently for different bricks. Errors: none.
#pragma once

#include <array>
#include <cstdint>
#include <span>

#include "distance/grid_crossings.hpp"
#include "distance/rim_cone.hpp"
#include "distance/winding_number.hpp"
#include "grid/brick_mask.hpp"
#include "grid/coord.hpp"
#include "grid/narrow_band.hpp"

namespace levelset {

inline constexpr double kAdaptiveTolerance = 0.1;

struct BrickWindingContext {
  const LazyWindingTree& tree;
  const GridFrame& frame;
  double beta = 2.0;
};

// Computes the crossings it needs into `scratch`.
BrickMask inside_from_reference(std::span<const GridTriangle> triangles,
                                std::span<const std::uint32_t> ids, const Coord& brick,
                                const BrickWindingContext& context, BrickCrossings& scratch,
                                std::uint64_t& queries);

// Computes the crossings it needs into `scratch`.
std::array<int, kBrickVoxels> relative_winding(std::span<const GridTriangle> triangles,
                                               std::span<const std::uint32_t> ids,
                                               const Coord& brick, BrickCrossings& scratch);

// `crossings`: all lines (kAllLines).

BrickMask inside_adaptive(const BrickCrossings& crossings, const Coord& brick,
                          std::span<const OpenSegment> rims, const BrickWindingContext& context,
                          std::uint64_t& queries);

}  // namespace levelset
