// The continuous part of an open surface's winding number near its rim, in closed form.
//
// Let S be an oriented triangle soup and N its open edges near a block of voxels, as rim
// segments a -> b in the order their triangles traverse them. For an apex A, the cone
// C = sum over N of the triangles (a, b, A) has the boundary N plus one segment between A and
// each end of N's chains. So S - C has no boundary near the block as long as those apex
// segments keep away from it: there, w_S - w_C is integer jumps (the signed crossings of S and
// of -C with the grid lines) plus a part whose singularities (the rims beyond N, the apex
// segments) are at least `clearance` away, smooth enough for a trilinear model. w_C itself is
// exact: one solid angle per segment.
//
// make_rim_cone
//   Inputs: rims (open edges, brick-local grid coordinates), the block [lo, lo + s)^3 (local
//   voxel indices), reach (N = the rims meeting the block's voxel-centre box grown by reach),
//   clearance (every apex segment must miss the box grown by clearance). Output: N and an apex
//   far along the first of 26 directions that keeps the apex segments clear, or nullopt (no
//   rim within reach, or no such direction). Chain ends are found by exact vertex positions.
// cone_winding(cone, p): w_C at local point p: sum of triangle_solid_angle / 4 pi. Undefined
//   (the mean of the two sides, 0 contribution) exactly on a cone triangle.
// cone_winding_block(cone, lo, s, out): w_C at every voxel of the block [lo, lo + s)^3 into
//   out[local_index(i, j, k)] (others untouched): the same sum with a polynomial arctangent
//   (|error| < 1e-7 per segment), vectorised over the voxels (built for AVX2 and AVX-512 too,
//   each clone giving the same IEEE operations in the same order).
// reversed_cone_triangles(cone, origin): the triangles (b, a, A) of -C in global grid space
//   (origin = the brick's origin), with exact normal signs, for brick_crossings.
// Cost: make_rim_cone O(|rims| + |N| log |N|); cone_winding O(|N|) (one atan2 per segment).
// Threading: pure. Errors: none.
#pragma once

#include <array>
#include <optional>
#include <span>
#include <vector>

#include "core/vec3.hpp"
#include "distance/grid_crossings.hpp"
#include "grid/coord.hpp"

namespace levelset {

using OpenSegment = std::array<Vec3d, 2>;

struct RimCone {
  std::vector<OpenSegment> segments;  // N, brick-local grid coordinates
  Vec3d apex;                         // brick-local grid coordinates
};

// Does segment [a, b] meet the box [lo, hi]? (Slab clipping; conservative at the boundary.)
bool segment_meets_box(const Vec3d& a, const Vec3d& b, const Vec3d& lo, const Vec3d& hi);

std::optional<RimCone> make_rim_cone(std::span<const OpenSegment> rims, const Coord& lo, int s,
                                     double reach, double clearance);

double cone_winding(const RimCone& cone, const Vec3d& p);

void cone_winding_block(const RimCone& cone, const Coord& lo, int s, double* out);

std::vector<GridTriangle> reversed_cone_triangles(const RimCone& cone, const Coord& origin);

}  // namespace levelset
