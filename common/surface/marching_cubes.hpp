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
// Units: world (the band's frame). Cost: one pass decoding every brick (2 KiB each) with its
//   inside mask at iso; a counting pass over the bricks whose cells can cross iso, from the
//   masks (O(11^2) bit rows per brick; values only for cells with an ambiguous face); a
//   writing pass that gathers their 11^3 tiles and writes O(output) straight into the result
//   at the prefix sums of the counts. Memory: ~2.5 KiB per brick besides the output.
// Threading: TBB over bricks in both passes; outputs sit in brick order, so vertex and
//   triangle arrays are identical for any thread count.
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
