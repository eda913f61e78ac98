// offset_surface: move a surface by a signed distance D along its normals (thesis 5.1.1,
// fig. 5.1): D > 0 grows the shape (dilation by a ball of radius D), D < 0 shrinks it
// (erosion). Topology may change: strands closer than 2D merge under a positive offset, and
// a later negative offset does not separate them again (+D then -D is a morphological
// closing, not the identity).
//
// Inputs: a NarrowBand (world distances, negative inside, W >= 2; W >= 3 for WENO5); options.
// Method: the level set equation with the constant speed beta = sign(D) (evolve/speed.hpp,
//   constant_speed) for the time |D| (evolve/evolution.hpp): scheme and time integration as
//   configured (default HJ-WENO5 with TVD-RK3, the accurate choice: a sphere's radius moves
//   by D within 0.1 voxel), then, by default, one redistance so the result is a clean
//   distance band again.
// Output: OffsetResult: the band (same frame), the evolution's counts.
// Units: D in world units (time = |D| because |beta| = 1).
// Cost: |D| / (cfl h / sqrt 3) steps, each O(active voxels) per RK stage.
// Threading: that of evolve and redistance: identical results for any thread count.
// Errors (thrown): Error{InvalidArgument} when D is 0 or not finite, |D| is more than
//   options.max_distance_voxels voxels, or the evolution options are bad; Error{Cancelled}
//   from the progress hook; Error{NonFinite} when the evolution met a NaN.
#pragma once

#include "core/progress.hpp"
#include "evolve/evolution.hpp"
#include "grid/narrow_band.hpp"

namespace levelset::apps {

struct OffsetOptions {
  double distance = 0;                             // D, world units, != 0
  evolve::Scheme scheme = evolve::Scheme::Weno5;
  int rk_order = 3;
  double cfl = 0;                                  // 0: the engine's default for rk_order
  int redistance_every = 0;                        // during the motion (0: by drift only)
  double drift_tolerance = 0.1;                    // redistance when the mean ||grad u|-1| exceeds it
  bool redistance_result = true;                   // one redistance at the end
  double max_distance_voxels = 100000;             // guard on |D| / h (steps grow with it)
  ProgressHook progress;
};

struct OffsetResult {
  NarrowBand band;
  int steps = 0;
  double time = 0;
  int redistance_count = 0;
  int landmine_count = 0;
  double seconds = 0;
};

OffsetResult offset_surface(const NarrowBand& band, const OffsetOptions& options);

}  // namespace levelset::apps
