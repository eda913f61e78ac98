// Which iso values a narrow band can contour faithfully.
//
// A cell crossed by the level {u = iso} has corners up to sqrt(3) h from that level, so its
// corners hold true values (not the clamped background W h) only while |iso| + sqrt(3) h < W h.
// Beyond that the extraction still runs (marching cubes accepts |iso| < W h) but the surface
// tears where the band is one voxel too thin: a sphere with W = 3 at iso 1.5 h came back open,
// at 2 h in 15 pieces. max_band_iso gives the bound; check_iso_in_band refuses beyond it.
// Units: world. Cost: O(1). Errors: Error{InvalidArgument} at `where` naming the bound and
// how to widen the band; Error{NonFinite} for NaN or infinite iso.
#pragma once

#include <string_view>

#include "grid/narrow_band.hpp"

namespace levelset {

double max_band_iso(const NarrowBand& band);

void check_iso_in_band(const NarrowBand& band, double iso, std::string_view where);

}  // namespace levelset
