// measure_mesh: area, volume, topology and triangle quality of an indexed triangle mesh.
//
// Inputs: a TriangleMesh (world units; indices must be < vertices.size()).
// Outputs (MeshMeasures): area; enclosed volume by the divergence theorem (signed: positive
//   for outward orientation, meaningful when watertight); vertices (referenced ones), edges,
//   faces and Euler characteristic chi = V - E + F; connected components (through shared
//   vertices); genus = (2 * components - chi) / 2, the sum of the component genera for a
//   closed orientable manifold (reported as is otherwise); boundary edges (1 triangle),
//   non-manifold edges (> 2 triangles), misoriented edges (2 triangles using the edge in the
//   same direction); non-manifold vertices (the link of triangles around the vertex is not a
//   single cycle); watertight (every edge in exactly 2 triangles), manifold (no non-manifold
//   edge or vertex), oriented (every edge used once in each direction); bounding box; quality:
//   smallest and mean minimum angle (degrees), largest aspect ratio (longest edge * perimeter
//   / (4 sqrt(3) area): 1 for equilateral, infinity for degenerate triangles).
// Cost: O(F) time (each vertex sorts only its own edges; 413k triangles of a reconstruction:
//   0.057 s, 0.14 s with one global edge sort), O(F) memory. Threading: TBB over fixed chunks
//   of triangles and vertices, combined in chunk order: the same results for any thread count.
// Errors: Error{InvalidArgument} for an index out of range.
#pragma once

#include <cstdint>

#include "core/bbox.hpp"
#include "io/triangle_mesh.hpp"

namespace levelset {

struct MeshMeasures {
  double area = 0.0;
  double volume = 0.0;
  std::uint64_t vertices = 0, edges = 0, faces = 0;
  std::int64_t euler_characteristic = 0;
  std::uint64_t components = 0;
  double genus = 0.0;
  std::uint64_t boundary_edges = 0, non_manifold_edges = 0, misoriented_edges = 0;
  std::uint64_t non_manifold_vertices = 0;
  bool watertight = false, manifold = false, oriented = false;
  BBox bounds;
  double min_angle_deg = 0.0, mean_min_angle_deg = 0.0, max_aspect_ratio = 0.0;
  std::uint64_t degenerate_triangles = 0;  // zero area
};

MeshMeasures measure_mesh(const TriangleMesh& mesh);

// area_weighted_mean_curvature: the area-weighted average of the mean curvature over a closed
//   triangle mesh, with the convention H = k1 + k2 (sum of the principal curvatures, NOT their
//   mean): a sphere of radius r gives 2/r; a torus (major R, minor r) gives 1/r.
// Method: the discrete integral of H over the surface is the sum over interior edges of
//   |e| * theta_e, theta_e the signed dihedral angle between the two face normals (positive
//   where the surface is convex with respect to its outward/face-orientation normals); it is
//   divided by the total area. Edges that are not shared by exactly two consistently oriented
//   triangles (boundary, non-manifold, misoriented) and edges next to a zero-area triangle
//   contribute nothing. Meaningful for closed, oriented meshes with outward orientation.
// Cost: O(F log F) time, O(F) memory. Threading: serial, reentrant.
// Errors: Error{InvalidArgument} for an index out of range; returns 0 for zero total area.
double area_weighted_mean_curvature(const TriangleMesh& mesh);

}  // namespace levelset
