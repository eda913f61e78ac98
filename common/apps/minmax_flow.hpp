// minmax_flow: feature-preserving smoothing to a steady state (thesis 3.3, eq. 3.9-3.10,
// after Malladi and Sethian): oscillations of the surface below a scale R are removed while
// larger features (edges, corners, the overall shape) stay.
//
// Speed (beta > 0 moves outward; H = k1 + k2 > 0 where the surface is convex), eq. 3.10:
//   beta = -max(H, 0)   where Avg_R(u) < G: only convex parts move (inward);
//   beta = -min(H, 0)   where Avg_R(u) >= G: only concave parts move (outward).
// Avg_R(u) is the average of u over the cube of (2R+1)^3 voxels centred on the voxel (a box
// filter, separable; band values, +-W h beyond the band). G is the thesis's "average
// perpendicular to the gradient": the value of the level set through the voxel, u itself
// for a distance function (u = 0 on the surface). For a distance function
// Avg_R(u) - u ~ (R h)^2 (R + 1) / (3 R) * H: the sign of the curvature smoothed over the
// scale R. So where the surface is concave at scale R the small convex bumps are cut down,
// where it is convex at scale R the small dents fill up; a shape convex at scale R (a large
// sphere, a box's faces, edges and corners) does not move: a steady state, which is what
// distinguishes the flow from mean curvature flow (which shrinks everything).
// What "smoothing" means here (measured, tests/unit/test_minmax_flow.cpp): on a shape convex
// at scale R the steady state is the local convex hull (thesis: -min(kappa, 0) "halts as
// soon as the convex hull is obtained"): dents fill, bump tips stay, the volume only grows
// (noisy sphere, R = 6: concave roughness / 3, volume +4%); the displacement of bumps taller
// than the scale-R curvature signal (h^2 R (R+1) / 3 * H) also enters Avg_R(u) - u, so R
// must be large enough for the shape's curvature to dominate (R = 3 left the noisy sphere
// as rough as before).
// The field handed to the speed (SpeedFields::roi) is Avg_R(u) - u.
// Inputs: a NarrowBand (world distances, negative inside, W >= 3); options.
// Method: chunks of options.update_every steps of evolve/evolution.hpp with a custom speed
//   reading Avg through SpeedFields::roi. Before each chunk Avg is computed for every active
//   voxel (TBB over bricks: a dense tile with an R-voxel halo, three 1D box passes); voxels the band upkeep activates
//   during the chunk compute theirs on demand from the same snapshot. So the switch lags the
//   surface by at most update_every steps (default 1: Avg from the state at the start of
//   the step). After each chunk the change is measured over the voxels within one voxel of
//   the zero level (active before and after): mean and max |u_new - u_old| per step, in
//   voxels. Steady state: the mean change per step falls below options.tolerance (voxels
//   per step) for options.patience consecutive chunks; or max_steps is reached.
// Output: MinMaxResult: the band, steps, time, whether a steady state was reached, and the
//   change history (one entry per chunk); before/after measures (apps/shape_measures.hpp)
//   when options.measure.
// Units: R in voxels; time in world units^2 (speed = curvature); change in voxels.
// Cost: per chunk one average pass O(bricks * (8 + 2R)^3) plus update_every evolution steps.
// Threading: TBB; identical results for any thread count.
// Errors (thrown): Error{InvalidArgument} for R not in [1, 16], tolerance <= 0 or not
//   finite, update_every < 1, max_steps < 1, patience < 1; Error{Cancelled} (progress hook,
//   between chunks and inside the evolution); Error{NonFinite} when a NaN entered the band.
#pragma once

#include <vector>

#include "apps/shape_measures.hpp"
#include "core/progress.hpp"
#include "grid/band_accessor.hpp"
#include "evolve/evolution.hpp"
#include "grid/narrow_band.hpp"

namespace levelset::apps {

struct MinMaxOptions {
  int radius = 3;               // R, voxels, in [1, 16]: the cube has 2R+1 voxels a side
  double tolerance = 1e-4;      // steady: mean |change| near the zero level < tolerance voxels per step
  int patience = 3;             // ... for this many consecutive chunks
  int update_every = 1;         // steps per chunk (Avg recomputed before each chunk)
  int max_steps = 2000;
  double cfl = 0;               // 0: the engine's default (forward Euler)
  int redistance_every = 10;    // steps (counted within a chunk, and at least once per chunk when > chunk)
  bool measure = true;
  ProgressHook progress;
};

struct MinMaxChunk {
  int step = 0;                 // steps completed after this chunk
  double time = 0;
  double mean_change = 0;       // voxels per step, mean over voxels near the zero level
  double max_change = 0;        // voxels per step, largest
};

struct MinMaxResult {
  NarrowBand band;
  int steps = 0;
  double time = 0;
  bool steady = false;
  int steady_step = 0;          // steps at which the steady criterion was met (0: not met)
  std::vector<MinMaxChunk> history;
  ShapeMeasures before, after;
  double seconds = 0;
};

MinMaxResult minmax_flow(const NarrowBand& band, const MinMaxOptions& options);

// Avg_R(u) at voxel c (world units): the mean of u over the (2R+1)^3 voxels of the cube centred on c.
double box_average(BandAccessor& accessor, const Coord& c, int radius_voxels);

}  // namespace levelset::apps
