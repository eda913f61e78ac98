// surface_nets: manifold dual contouring of a narrow band (one vertex per cell loop).
//
// Inputs: a NarrowBand (world distances, negative inside); options.iso with |iso| <
//   background(); options.relax_iterations (>= 0) Newton steps towards the level set.
// Method: every contoured cell (8 active corners) gets one vertex per contour loop of
//   surface/cell_loops.hpp (the loops marching_cubes triangulates: Manifold Dual Contouring,
//   Schaefer, Ju & Warren 2007), placed at the mean of the loop's edge crossings and then moved
//   by Newton steps p -= (phi - iso) grad / |grad|^2 on the trilinear interpolant, clamped to
//   the cell. Every grid edge crossing the iso level whose 4 surrounding cells are contoured
//   yields a quad between the loop vertices of those cells that contain the crossing, split
//   into two triangles along its Delaunay diagonal (the larger smallest angle for a planar
//   quad), oriented with normals to the positive side. Normals: the interpolated level set
//   gradient at each vertex.
//   Split loops: when a loop holds both segments of an ambiguous face and the cell across
//   that face has such a loop too, one vertex per loop would put both sheets through that
//   face on one dual edge (4 triangles). Such a loop gets one vertex per loop edge instead
//   (midway between the crossing and the loop centre, then projected), a cap polygon through
//   them (fanned for the best smallest angle), and seam triangles / quads to the neighbour's
//   vertices across each of its faces. Rare on smooth fields; about 1% of cells on random
//   ones.
// Output: SurfaceResult (surface/surface_result.hpp); world units.
// Guarantees: watertight, manifold and consistently oriented wherever the iso-surface lies
//   inside the contoured cells, with the topology (components, Euler characteristic) of
//   marching_cubes on the same band; tested on random and checkerboard fields and on every
//   closed CGAL sample mesh.
// Cost: O(bricks * 11^3) plus O(output). Threading: TBB over bricks, per-brick buffers merged
//   in brick order: identical arrays for any thread count.
// Errors: Error{InvalidArgument} for a bad iso or relax_iterations < 0; Error{Cancelled}
//   through options.progress; Error{LimitExceeded} beyond 2^32 - 1 vertices.
#pragma once

#include "core/progress.hpp"
#include "grid/narrow_band.hpp"
#include "surface/surface_result.hpp"

namespace levelset {

struct SurfaceNetsOptions {
  double iso = 0.0;
  int relax_iterations = 3;
  ProgressHook progress;
};

SurfaceResult surface_nets(const NarrowBand& band, const SurfaceNetsOptions& options = {});

}  // namespace levelset
