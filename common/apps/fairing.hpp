// fair_surface: smooth a surface with a curvature flow (thesis 3.1, 5.1.2) and report how
// rough it was before and after.
//
// Flows (evolve/speed.hpp; beta > 0 moves outward, H = k1 + k2 > 0 on a sphere):
//   MeanCurvature     beta = -H: smooths and shrinks; a sphere follows r^2 = r0^2 - 4 t;
//                     thin necks pinch off (topology may change).
//   MeanGaussian      beta = -sign(H) sqrt(max(K, 0)) (eq. 3.4 / 5.2): moves only where the
//                     surface is elliptic (K > 0), so saddles and necks stay: no pinching; a
//                     sphere shrinks at speed 1/r (r^2 = r0^2 - 2 t).
//   VolumePreserving  beta = -(H - mean H) (eq. 3.5): smooths towards a sphere, the enclosed
//                     volume constant up to discretisation (~1% over a fairing run).
// Inputs: a NarrowBand (world distances, negative inside, W >= 3); options: the flow and
//   exactly one of time (world time units) or steps.
// Method: evolve/evolution.hpp with the flow's speed (forward Euler, first-order upwinding
//   for the hyperbolic part by default: the flows are parabolic, the explicit step is
//   dt = h^2 / (6 b) times cfl), redistancing every redistance_every steps; measures of the
//   zero level (apps/shape_measures.hpp) before and after when options.measure.
// Output: FairingResult: the band (same frame), steps and time run, before/after measures.
// Units: world; time in world units^2 for these flows (speed = curvature).
// Cost: steps x O(active voxels) (27-point curvature stencils), plus two meshings.
// Threading: identical results for any thread count.
// Errors (thrown): Error{InvalidArgument} for both or neither of time/steps, negative or
//   non-finite values, steps > max_steps; Error{Cancelled} (progress hook); Error{NonFinite}
//   when a NaN entered the band.
#pragma once

#include <string>
#include <string_view>

#include "apps/shape_measures.hpp"
#include "core/progress.hpp"
#include "evolve/evolution.hpp"
#include "grid/narrow_band.hpp"

namespace levelset::apps {

enum class FairingFlow { MeanCurvature, MeanGaussian, VolumePreserving };

// "mean-curvature", "mean-gaussian", "volume-preserving"; Error{InvalidArgument} otherwise.
FairingFlow fairing_flow_from_name(std::string_view name);
std::string_view fairing_flow_name(FairingFlow flow);

struct FairingOptions {
  FairingFlow flow = FairingFlow::MeanCurvature;
  double time = 0;                  // world time units, or ...
  int steps = 0;                    // ... a step count (exactly one of the two > 0)
  int max_steps = 1000000;          // cap for time-driven runs
  evolve::Scheme scheme = evolve::Scheme::Upwind1;
  int rk_order = 1;
  double cfl = 0;                   // 0: the engine's default
  int redistance_every = 10;
  bool measure = true;              // before/after measures (two meshings)
  ProgressHook progress;
};

struct FairingResult {
  NarrowBand band;
  int steps = 0;
  double time = 0;
  int redistance_count = 0;
  ShapeMeasures before, after;      // zeros when !options.measure
  double seconds = 0;
};

FairingResult fair_surface(const NarrowBand& band, const FairingOptions& options);

}  // namespace levelset::apps
