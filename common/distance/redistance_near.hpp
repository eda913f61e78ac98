// redistance_near: redistance a narrow band only around a few changed voxels (the band's
// distances hold elsewhere), at the cost of the bricks around them instead of the whole band.
//
// Inputs: a NarrowBand whose values are a signed distance (half-width W = its frame's) except
//   near the voxels `changed` (voxel indices, any order, duplicates allowed): e.g. the voxels
//   whose flips a topology guard refused, left at +-eps; RedistanceNearOptions below.
// Output: the band with the same topology (active voxels, bricks, stored signs) whose values
//   in the bricks within one brick (26-neighbourhood) of a changed voxel's brick are
//   redistance()'s of the sub-band of the bricks within two bricks (same options, half-width W,
//   no growth): the distance to the zero level set within W (>= 1 voxel, <= 8) of those
//   voxels holds the band's whole zero level within W. A voxel the sub-band's redistance left
//   beyond W keeps its sign at +-W h (the band's edge). Every voxel keeps its sign; other
//   values are unchanged bit for bit. When the bricks within two bricks are more than
//   `max_share` of the band's, the whole band is redistanced the same way (still no growth).
// Cost: O(voxels of those bricks) plus O(bricks) to find them. Threading: redistance()'s
//   (TBB), results independent of the thread count.
// Errors: redistance()'s; Error{InvalidArgument} for a band half-width above 8 (the one-brick
//   reach) or a changed voxel outside the band's bricks.
#pragma once

#include <vector>

#include "distance/redistance.hpp"

namespace levelset {

struct RedistanceNearOptions {
  int order = 2;            // as RedistanceOptions
  double tolerance = 1e-6;  // as RedistanceOptions
  double max_share = 0.5;   // of the band's bricks: beyond it, the whole band
  ProgressHook progress;
};

struct RedistanceNearResult {
  NarrowBand band;
  std::size_t bricks_redistanced = 0;  // bricks whose values were replaced
};

RedistanceNearResult redistance_near(NarrowBand band, const std::vector<Coord>& changed,
                                     const RedistanceNearOptions& options);

}  // namespace levelset
