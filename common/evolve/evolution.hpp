// evolve: move a narrow band's zero level with the level set equation (thesis 2.2, 2.4, 4.4)
//
//   u_t + beta_a |grad u|_upwind + beta_p |grad u|_central + V . grad u = 0
//
// with beta_a, beta_p from a SpeedFunction (evolve/speed.hpp) and V an optional advection
// velocity, on the band only, keeping the band centred on the moving front.
//
// Inputs: a NarrowBand (world distances, negative inside, half-width W >= 2 voxels: the
//   schemes read 3 voxels around each active voxel, the band edge supplies +-W h there);
//   EvolutionOptions below.
// Method, per step:
//   1. Spatial operator L(u) per active voxel, brick by brick on a dense 14^3 tile: upwind
//      one-sided derivatives (Upwind1 = the thesis's first-order Godunov scheme, HJ-ENO2,
//      HJ-WENO5; evolve/derivatives.hpp) combined by Godunov's Hamiltonian for beta_a (or
//      Local Lax-Friedrichs with alpha = |beta_a| + |V_a| when requested) and by upwinding
//      for V; curvatures (evolve/curvature.hpp) by central differences, only those the speed
//      needs, with the parabolic part on the central |grad u|.
//   2. dt = cfl / (h_rate / h + 6 b / h^2) (cfl by default 0.5 for forward Euler, the
//      thesis's h / (2 beta); 0.9 for TVD-RK3, which is stable there) from the largest hyperbolic rate
//      (sqrt(3) |beta_a| + |V|_1) and the speed's diffusion bound b (thesis eq. 4.7 for the
//      hyperbolic part; the explicit parabolic limit h^2 / (6 b)); for options.time the last
//      step ends exactly at T. Forward Euler, or TVD-RK3 (Shu-Osher) with the same dt.
//   3. Land mines (thesis 2.4): a voxel at the band's edge (an inactive 6-neighbour) whose
//      sign changed means the front reached the edge; the step is redone with dt / 2 (up
//      to 4 times; counted), and the band is redistanced after it.
//   4. The band's edge layer (an inactive 6-neighbour) is not left to the PDE, whose
//      stencils there read +-W h beyond the band: it takes the quadratic extrapolation of
//      the new interior values along the axis nearest the normal, every step. Band upkeep
//      (evolve/band_tracking.hpp: voxels the front approaches activated, voxels it left
//      retired, in work proportional to the band, no rebuild from a mesh) runs once the
//      front may have moved track_distance voxels since the last one (sum of
//      dt * max |speed|), and after a land mine.
//   5. Redistance (distance/redistance.hpp, fast sweeping, zero level kept) every
//      redistance_every steps, whenever the mean ||grad u| - 1| over the voxels within
//      2 h of the zero level exceeds drift_tolerance (on by default: 0.05), and whenever
//      the band holds more than band_growth_limit (default 1.5) times the voxels a fresh
//      band of the same surface would (active voxels per zero crossing, measured after each
//      redistance). With the defaults the band stays bounded for any number of steps.
//   Curvatures near the band's edge, where the 19-point stencil would read inactive
//   samples, are taken from the nearest voxel toward the front with a whole stencil (the
//   curvature of a parallel level set); see curvature_source in evolution.cpp.
//   Extension velocities (thesis 2.3.5, options.extension): the speeds are first computed
//   on the band, then every voxel takes the (trilinearly interpolated) speeds at its
//   closest point x - u n on the zero level, so the speed is constant along normals and the
//   distance property is kept.
// Output: EvolutionResult; the band after the last completed step (never a partial step).
// Stopping: steps reached, time reached, max_steps, stop_when returning true after a step
//   (stop = Completed, message says so; for convergence tests), the cancel token (checked
//   between steps: stop = Cancelled), a NaN/Inf entering the band (stop = NonFinite with a message naming
//   the step and voxel; the band is the last good state), or no zero crossing left in the band
//   (stop = Vanished: the surface shrank away; the band is returned empty with the remaining
//   sign). Nothing is thrown for these.
// Units: world units and time; StepInfo.dt in time units.
// Cost per step: O(active voxels) per RK stage (x3 for RK3) plus the band upkeep O(active
//   voxels + bricks log bricks); curvatures add a 27-point stencil and, for K/k1/k2, a 2x2
//   eigen-solve per voxel. Memory: about 3 value arrays besides the band.
// Threading: TBB over bricks; results are identical for any thread count.
// Errors (thrown): Error{InvalidArgument} for bad options (no motion given, both or neither
//   of steps/time, cfl not in (0, 1], rk_order not 1 or 3, W < 2, negative counts,
//   band_growth_limit not 0 or in [1, 1e6]).
#pragma once

#include <cstdint>
#include <functional>
#include <string>

#include "core/progress.hpp"
#include "core/vec3.hpp"
#include "evolve/derivatives.hpp"
#include "evolve/speed.hpp"
#include "grid/narrow_band.hpp"

namespace levelset::evolve {

enum class Hamiltonian { Godunov, LaxFriedrichs };

// Advection velocity (world units per time).
struct Velocity {
  enum class Kind { None, Constant, Field } kind = Kind::None;
  Vec3d constant{};
  std::function<Vec3d(const Vec3d& world, double time)> field;  // called concurrently
};

struct StepInfo {
  int step = 0;                 // 1-based, completed steps
  double time = 0, dt = 0;
  std::uint64_t active_voxels = 0;
  double max_speed = 0;         // largest |beta_a| + |beta_p| + |V| this step
  int redistance_count = 0;
  int landmine_count = 0;
  double grad_drift = 0;        // mean ||grad u| - 1| within 2 h of the zero level (before upkeep)
  std::uint64_t crossings = 0;  // grid edges across the zero level at the step's start (area / h^2 times |n|_1)
  double elapsed_seconds = 0;
  // The band after this step, valid during the callback only (viewers, tests).
  const NarrowBand* band = nullptr;
};

// StepObserverScope: while it lives, every evolution run on the calling thread reports each
// step to `observer` too (after options.on_step). The daemon watches jobs with it whose
// applications run the evolution inside (offset, fairing, min/max, CSG seams, reconstruction,
// segmentation) to publish live previews without a hook in each application's options.
// Scopes nest; the innermost observes. Not copyable; thread-local by design.
class StepObserverScope {
 public:
  explicit StepObserverScope(std::function<void(const StepInfo&)> observer);
  ~StepObserverScope();
  StepObserverScope(const StepObserverScope&) = delete;
  StepObserverScope& operator=(const StepObserverScope&) = delete;

 private:
  std::function<void(const StepInfo&)> observer_;
  const std::function<void(const StepInfo&)>* previous_;
};

// Default drift tolerance: redistance once the mean ||grad u| - 1| near the front passes it.
// Measured on mean-curvature flow of a sphere to half its radius (R = 64 and 128): 0.02-0.1
// all keep the radius within 0.5 % of sqrt(r0^2 - 4t); without it the flow's own stretching
// of the level sets (|grad u| -> r / r0) went unchecked.
inline constexpr double kDefaultDriftTolerance = 0.05;
// Default band growth guard: redistance when the band holds more than this many times the
// voxels of a fresh band around the same surface.
inline constexpr double kDefaultBandGrowthLimit = 1.5;

struct EvolutionOptions {
  SpeedFunction speed;          // no eval: no normal motion
  SpeedFields fields;           // those the speed reads
  Velocity velocity;
  Scheme scheme = Scheme::Upwind1;
  Hamiltonian hamiltonian = Hamiltonian::Godunov;
  int rk_order = 1;             // 1: forward Euler, 3: TVD-RK3
  double cfl = 0.0;             // in (0, 1]; 0: 0.5 for forward Euler, 0.9 for TVD-RK3
  int steps = 0;                // run this many steps, or ...
  double time = 0;              // ... until this time (exactly one of the two > 0)
  int max_steps = 1000000;      // cap for time-driven runs
  int redistance_every = 0;     // 0: not by count
  double drift_tolerance = kDefaultDriftTolerance;  // 0: not by drift
  // Redistance when the active voxels exceed this many times a fresh band's count for the
  // current surface (estimated from the zero crossings, see StepInfo::crossings); 0: off.
  double band_growth_limit = kDefaultBandGrowthLimit;
  bool extension = false;
  double track_distance = 0.5;  // voxels the front may move between band upkeeps, in (0, 1]
  std::function<void(const StepInfo&)> on_step;  // after every step, from the calling thread
  // After every step (after on_step), from the calling thread: true ends the run there
  // (stop = Completed). Empty: never. The band is tidied as for any other end.
  std::function<bool(const StepInfo&)> stop_when;
  ProgressHook progress;        // fraction of steps / time; cancel checked between steps
};

// Vanished: no sign change is left in the band (the surface shrank to nothing, or the input
// had none); the band is then emptied, its sign everywhere the one that remained.
// Stopped: options.progress.stop fired (checked before each step); the band is the state
// reached, tidied as for any other end.
enum class StopReason { Completed, Cancelled, NonFinite, Vanished, Stopped };

struct EvolutionSeconds {
  double operator_eval = 0;     // derivatives, curvature, speed, per-voxel rates (all stages)
  // The operator's phases in CPU seconds summed over threads (wall time with 1 thread):
  double gradient_cpu = 0;      // tiles, upwind and central derivatives, edge stencils
  double curvature_cpu = 0;     // H, or H, K, k1, k2
  double speed_cpu = 0;         // the speed function
  double rates_cpu = 0;         // Hamiltonians and rates
  double update = 0;            // RK combinations, checks
  double tracking = 0;          // band upkeep
  double redistance = 0;
  double total = 0;
};

struct EvolutionResult {
  NarrowBand band;
  int steps = 0;
  double time = 0;
  int redistance_count = 0;
  int growth_redistance_count = 0;  // of those, by the band growth guard
  int landmine_count = 0;
  std::uint64_t activated = 0, retired = 0;  // by the band upkeep, all steps
  int band_updates = 0;         // band upkeeps run
  double grad_drift = 0;        // at the last step
  StopReason stop = StopReason::Completed;
  std::string message;          // why it stopped early
  EvolutionSeconds seconds;
};

EvolutionResult evolve(const NarrowBand& band, const EvolutionOptions& options);

// "completed", "cancelled", "non-finite".
std::string_view to_string(StopReason reason);

// For callers that treat an interrupted run as a failure: throws Error{Cancelled} or
// Error{NonFinite} (with the run's message) at `where` when the run stopped so.
void throw_if_stopped(const EvolutionResult& result, const std::string& where);

}  // namespace levelset::evolve
