// Step 1 of redistance() (redistance.hpp, Method 1): subcell-accurate distances of the
// interface voxels, which then stay fixed so that the zero level does not move.
//
// init_interface(in, w)
//   Inputs: the input band and its domain from build_domain (dist = kInf, no fixed voxels).
//   Output: for every active input voxel with a 6-neighbour of opposite sign, w.dist holds
//   its unsigned distance to the zero level in voxels (<= 1; the second-order Taylor
//   estimate along the normal where the 3x3x3 stencil is active and it agrees with the
//   plane through the edge crossings to 0.1 voxel, that plane's distance otherwise) and
//   w.fixed has its bit set. Returns the number of such voxels.
// Cost: O(active input voxels) plus one halo-1 tile gather per input brick with active
//   voxels. Threading: TBB, per brick in parallel (each writes only its own brick).
// Errors: none.
#pragma once

#include <cstdint>

#include "distance/redistance_domain.hpp"
#include "grid/narrow_band.hpp"

namespace levelset::detail {

std::uint64_t init_interface(const NarrowBand& in, RedistanceDomain& w);

}  // namespace levelset::detail
