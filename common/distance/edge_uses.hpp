// sorted_edge_uses: the uses of a triangle soup's undirected edges, grouped by edge; what
// orient_faces (manifold links), open_edges (net direction per edge) and the characteristic
// scan's adjacency (the triangle across each edge, vertex rings) read.
//
// Inputs: the mesh's triangles; ids: per vertex its id for edges (weld_exact's welded ids, or
//   the indices themselves), each < ids.size(); counted: per triangle whether its edges are
//   taken (empty: all).
// Output: one EdgeUse per edge k (from corner k to corner k + 1) of every counted triangle,
//   lo / hi its smaller / larger end id (uses with lo == hi included), ordered by
//   (lo, hi, face, slot): the uses of one undirected edge are consecutive.
// Method: a counting sort on lo (uses are made in face and slot order, so each bucket is in
//   that order already), then within each bucket a stable sort on hi (insertion sort: a
//   vertex has a handful of edges; std::sort on the whole order for a fan's apex).
// Cost: O(F + V) time beyond the fans, 16 bytes per use plus 4 per id. Threading: none.
// Errors: none (indices and ids must be valid).
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "io/triangle_mesh.hpp"

namespace levelset {

struct EdgeUse {
  std::uint32_t lo = 0, hi = 0;  // end ids, lo <= hi
  std::uint32_t face = 0;
  std::uint8_t slot = 0;         // edge k of the face: (corner k, corner k + 1)
  bool forward = false;          // the face traverses it from lo to hi (lo < hi)
  bool same_edge(const EdgeUse& o) const { return lo == o.lo && hi == o.hi; }
  bool operator<(const EdgeUse& o) const {
    if (lo != o.lo) return lo < o.lo;
    if (hi != o.hi) return hi < o.hi;
    if (face != o.face) return face < o.face;
    return slot < o.slot;
  }
};

std::vector<EdgeUse> sorted_edge_uses(const TriangleMesh& mesh, std::span<const std::uint32_t> ids,
                                      const std::vector<bool>& counted = {});

}  // namespace levelset
