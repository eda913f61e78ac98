// track_band: keep a narrow band centred on a moving zero level (thesis 2.4), without any
// rebuild from a mesh: after a time step has changed the values (less than a voxel of
// motion), voxels the front approaches are activated and voxels it left are retired.
//
// Input: `moved`, a band whose active values were just updated in place (its topology is the
//   previous step's; the band invariant must still hold: no sign change at the band's edge,
//   which the evolution's land mines check); half_width W in voxels.
// Output: a band with the same frame and W holding every voxel of the 26-dilated active set
//   whose |value| <= W h: previously active voxels keep their values, except the edge layer
//   (an inactive 6-neighbour: its stencils read +-W h beyond the band, so its values lag and
//   on the upwind side of a moving front would never pass W h), which is extrapolated
//   linearly from the interior along the axis nearest the normal; a newly reached voxel
//   gets sign * (|u_n| + h) from its nearest previously active 6-neighbour n (a distance-like
//   extrapolation; periodic redistancing makes it exact); bricks left empty are dropped (the
//   row rule keeps their sign). Counts of activated and retired voxels.
// Cost: O(active voxels + bricks log bricks) per call; memory 4 bytes per voxel of the
//   dilated bricks. Threading: TBB over bricks; results identical for any thread count.
// Errors: Error{LimitExceeded} when the dilation leaves the index range; Error{Cancelled}.
#pragma once

#include <cstdint>

#include "core/progress.hpp"
#include "grid/narrow_band.hpp"

namespace levelset::evolve {

struct TrackOptions {
  double half_width = 3.0;  // voxels
  // Re-extrapolate the edge layer (off when the caller keeps it fresh itself, as evolve does).
  bool extrapolate_edge = true;
  ProgressHook progress;
};

struct TrackResult {
  NarrowBand band;
  std::uint64_t activated = 0;
  std::uint64_t retired = 0;
};

TrackResult track_band(const NarrowBand& moved, const TrackOptions& options);

}  // namespace levelset::evolve
