// orient_faces: consistent, outward orientation of the faces of a triangle soup.
//
// Inputs: a mesh (world units; any soup). Options: a progress hook (checked between phases).
// Output: a copy of the mesh in which
//   - faces are consistent across manifold edges (an edge used by exactly two non-degenerate
//     faces is traversed in opposite directions by them), propagated by breadth-first search per
//     connected component: the seed is the lowest face index not yet reached, the queue is
//     first-in first-out and the neighbours of a face are enqueued in increasing face index;
//     where a component is not orientable (Moebius strips) the first assignment wins;
//   - each component is then flipped as a whole when its signed volume about its own
//     area-weighted centroid is negative, so closed components get outward normals.
//   Edges are identified by their end points' positions: vertices with exactly equal
//   coordinates count as one (weld_exact), so split vertices along texture or normal seams
//   still connect; the output keeps the input's vertex indices.
//   Components are the classes of non-degenerate faces connected through manifold edges.
//   Non-manifold edges (3 or more faces) and boundary edges do not propagate orientation.
//   Degenerate faces (a repeated vertex or an exactly zero cross product) are kept as
//   they are and neither propagate nor count in any component. A flip swaps a face's second
//   and third index; vertices and face order are unchanged.
// Cost: O(F + V) expected time (a counting sort of 3F edge records by their lower vertex, a
//   hash table for the weld), O(F + V) memory.
// Threading: none (it runs beside the closest point transform's scan).
// Errors: Error{InvalidArgument} for vertex indices out of range, Error{NonFinite} for NaN or
//   Inf vertices, Error{LimitExceeded} for 2^32 or more faces, Error{Cancelled} from the
//   progress hook.
#pragma once

#include <cstdint>

#include "core/progress.hpp"
#include "io/triangle_mesh.hpp"

namespace levelset {

struct OrientOptions {
  ProgressHook progress;
  // The caller guarantees that vertices at equal positions already share one index (e.g.
  // unique_faces' output): the exact weld is skipped.
  bool welded = false;
};

struct OrientResult {
  TriangleMesh mesh;                     // consistently oriented copy
  std::uint32_t components = 0;          // connected components of non-degenerate faces
  std::uint64_t faces_flipped = 0;       // faces whose orientation differs from the input
  std::uint64_t degenerate_faces = 0;    // kept as they are
  std::uint64_t nonmanifold_edges = 0;   // edges with 3 or more faces
  std::uint64_t inconsistent_edges = 0;  // manifold edges left inconsistent (non-orientable)
};

// The mesh is taken by value: pass a temporary (or std::move) to orient it without a copy.
OrientResult orient_faces(TriangleMesh mesh, const OrientOptions& options);

}  // namespace levelset
