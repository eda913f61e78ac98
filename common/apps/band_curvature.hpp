// band_mean_curvature: the mean curvature H = k1 + k2 of a narrow band's level sets at an
// arbitrary world point (for measuring surfaces, not for evolving them).
//
// Inputs: a NarrowBand (world distances, negative inside), an accessor on it, a finite world
//   point p, ideally within 1 voxel of the zero level of a band with half-width W >= 3 (the
//   stencils read 2 voxels around the cell of p; beyond the band they see +-W h and the answer
//   is meaningless there).
// Method: H at each of the 8 voxels of the cell holding p by the central-difference trace form
//   (evolve/curvature.hpp, mean_curvature_at on a 3x3x3 gather), then trilinear interpolation.
// Units: 1 / world units (a sphere of radius r gives 2 / r). Cost: 8 x 27 accessor reads.
// Threading: one BandAccessor per thread. Errors: Error{NonFinite} for a non-finite p.
#pragma once

#include "core/vec3.hpp"
#include "grid/band_accessor.hpp"

namespace levelset::apps {

double band_mean_curvature(BandAccessor& accessor, const NarrowBand& band, const Vec3d& p);

}  // namespace levelset::apps
