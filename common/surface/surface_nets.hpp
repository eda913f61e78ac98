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
//   into two triangles along the diagonal with the larger smallest angle, oriented with normals
//   to the positive side. Normals: the interpolated level set gradient at each vertex.
// Output: SurfaceResult (surface/surface_result.hpp); world units.
// Guarantees: watertight and consistently oriented wherever the iso-surface lies inside the
//   contoured cells; manifold except where two cells sharing an ambiguous face both have one
//   loop holding both of that face's segments (then that dual edge has 4 triangles; measured
//   by the tests on random fields).
// Cost: O(bricks * 12^3) plus O(output). Threading: TBB over bricks, per-brick buffers merged
//   in brick order: identical arrays for any thread count.
// Errors: Error{InvalidArgument} for a bad iso or relax_iterations < 0; Error{Cancelled}
//   through options.progress.
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
