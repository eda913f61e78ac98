// marching_cubes: the iso-surface of a narrow band as an indexed, watertight triangle mesh.
//
// Inputs: a NarrowBand (world distances, negative inside) and options.iso, a world distance
//   with |iso| < background() (the band limit W*h).
// Cells: unit cubes between 8 voxel centres; only cells whose 8 corners are all active are
//   contoured (a cell with an inactive corner is skipped).
// Output: SurfaceResult (surface/surface_result.hpp): one vertex per grid edge that crosses
//   the iso level (value < iso is inside; ties are outside) and belongs to a contoured cell,
//   placed by linear interpolation; per-vertex normals from the level set gradient (central
//   differences at the edge ends, interpolated along the edge, normalised); triangles
//   oriented with normals to the positive side. Each cell's contour is a set of closed loops
//   (surface/cell_loops.hpp: face segments paired by the asymptotic decider, identical for the
//   two cells sharing a face). A loop is fanned from the vertex that maximises the smallest
//   angle (a quad: its Delaunay diagonal); a loop holding both segments of an ambiguous face gets one extra vertex at its
//   centroid instead (counted in extra_vertices), so that no diagonal is shared by two cells.
//   The mesh is watertight, manifold and consistently oriented wherever the iso-surface lies
//   inside the contoured cells.
// Units: world (the band's frame). Cost: O(bricks * 11^3) for the bricks whose cells can
//   cross iso (others are skipped after one pass over the values) plus O(output).
// Threading: TBB over bricks; per-brick buffers merged in brick order, so vertex and triangle
//   arrays are identical for any thread count.
// Errors: Error{InvalidArgument} when |iso| >= background() or iso is not finite;
//   Error{Cancelled} through options.progress (checked between brick batches).
#pragma once

#include "core/progress.hpp"
#include "grid/narrow_band.hpp"
#include "surface/surface_result.hpp"

namespace levelset {

struct MarchingCubesOptions {
  double iso = 0.0;
  ProgressHook progress;
};

SurfaceResult marching_cubes(const NarrowBand& band, const MarchingCubesOptions& options = {});

}  // namespace levelset
