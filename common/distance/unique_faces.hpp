// unique_faces: the faces that matter for inside/outside, once each.
//
// Input: a triangle mesh. Output: a copy whose vertices are welded where their coordinates
// are exactly equal, in which degenerate faces (a repeated vertex after welding, or an exactly
// zero cross product) and repeated faces are collapsed to a point (a, a, a), so that face
// indices stay those of the input. Copies of a face (the same three welded vertices) add up
// by orientation: one copy of the net orientation stays, none when opposite copies cancel
// (a double-sided sheet encloses nothing). Winding numbers of a soup count every copy of a face,
// so a duplicated face would otherwise change inside/outside near it; distances do not
// depend on this (the closest point transform uses the mesh as given).
// Cost: O(V + F) expected (hash tables of positions and of vertex sets; only faces met more
//   than once are sorted). Threading: none. Errors: Error{LimitExceeded} for 2^32 - 1 or more
//   vertices (weld_exact), else none beyond bad_alloc.
#pragma once

#include "io/triangle_mesh.hpp"

namespace levelset {

struct UniqueFacesResult {
  TriangleMesh mesh;
  std::uint64_t degenerate_removed = 0;
  std::uint64_t duplicates_removed = 0;
};

UniqueFacesResult unique_faces(const TriangleMesh& mesh);

}  // namespace levelset
