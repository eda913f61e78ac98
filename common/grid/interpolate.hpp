// sample_trilinear: the level set's value at an arbitrary world point.
//
// Trilinear interpolation of the 8 voxels around p (index space (p - origin)/h). Voxels
// outside the band contribute +-background() by their sign, so far from the band the result
// is the band limit with the right sign; it is never NaN for finite p. Points beyond the
// index range take the far sign. Cost: 8 accessor reads (usually one brick, no hashing).
// Threading: one BandAccessor per thread. Errors: Error{NonFinite} for a non-finite p.
#pragma once

#include "grid/band_accessor.hpp"

namespace levelset {

float sample_trilinear(BandAccessor& accessor, const NarrowBand& band, const Vec3d& p);

}  // namespace levelset
