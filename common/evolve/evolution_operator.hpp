// The spatial operator of evolve() (evolution.hpp): for every active voxel of a band, the
// rate du/dt of the level set equation from the speed and / or the velocity, with the
// quantities the step loop needs (CFL bounds, front speed, |grad u| drift, sign changes, the
// edge layer's extrapolation stencils).
//
// run_operator(band, setup)
//   Inputs: the band (world distances) and the options; setup.time for time-dependent
//   velocities; setup.kavg (kavg in formulas); optional extension velocities (band value
//   order) replacing the speed's own betas.
//   Output: OperatorOutput (rates in band value order; reductions; per-phase CPU seconds).
//   Cost: O(bricks * tile) for the gathers plus O(active voxels * stencil). Threading: TBB
//   over bricks, per-thread scratch; results do not depend on the thread count.
// mean_curvature_average(band): the area-weighted mean of H over the zero level (kavg).
// extend_speeds(band, beta_a, beta_p): the speeds extended from the zero level (each voxel
//   takes them at its closest point); both vectors in band value order, replaced.
//   These two live in front_fields.cpp.
// Internal to levelset_core (namespace evolve::detail).
#pragma once

#include <array>
#include <cstdint>
#include <limits>
#include <vector>

#include "core/uninitialized_vector.hpp"
#include "evolve/evolution.hpp"
#include "grid/narrow_band.hpp"

namespace levelset::evolve::detail {

// The band's edge layer is not evolved by the PDE (its stencils read +-W h beyond the band):
// after each step an edge voxel takes the polynomial extrapolation of the new values along
// the axis direction where u changes fastest: sum of coef[k] * u[source[k]].
struct EdgeStencil {
  std::uint32_t target = 0;
  std::uint8_t count = 0;
  std::array<std::uint32_t, 3> source{};
  std::array<float, 3> coef{};
  // The active 6-neighbours: a distance changes by at most h per voxel, so the result is
  // clamped to the range they allow (a polynomial through a kink could leave it).
  std::uint8_t neighbors = 0;
  std::array<std::uint32_t, 6> neighbor{};
  // The new value of target, written by the step's extrapolation before any target is
  // (sources and neighbours may be edge voxels themselves: all read the step's values).
  float value = 0;
};

// CPU seconds summed over threads, per phase of the spatial operator.
struct OperatorSeconds {
  double gradient = 0, curvature = 0, speed = 0, rates = 0;
};

struct OperatorSetup {
  const EvolutionOptions& options;
  double time = 0, kavg = 0;
  const float* beta_a_override = nullptr;  // band value order (extension velocities)
  const float* beta_p_override = nullptr;
  bool want_edges = false;
  bool want_betas = false;  // fill OperatorOutput::beta_a / beta_p
  // The reductions (CFL and speed bounds, |grad u| drift, value range): off for RK3's later
  // stages, which use the rates only.
  bool want_stats = true;
};

struct OperatorOutput {
  UninitializedVector<float> rate;  // every active voxel's entry is written
  std::vector<float> beta_a, beta_p;
  std::vector<std::uint8_t> edge;  // 1: an active voxel with an inactive 6-neighbour
  std::vector<std::vector<EdgeStencil>> edge_stencils;  // per brick
  double max_hyperbolic = 0, max_speed = 0, max_front_speed = 0, drift_sum = 0;
  std::uint64_t drift_count = 0;
  // Grid edges between 6-neighbours of opposite sign (want_edges only): a measure of the zero
  // level's area, about A / h^2 times |n|_1, that does not depend on |grad u|.
  std::uint64_t crossings = 0;
  float min_value = 0, max_value = 0;  // over the active voxels (want_edges only)
  OperatorSeconds seconds;
};

inline bool has_velocity(const EvolutionOptions& o) { return o.velocity.kind != Velocity::Kind::None; }
inline bool has_speed(const EvolutionOptions& o) { return bool(o.speed.eval); }

double mean_curvature_average(const NarrowBand& band);
OperatorOutput run_operator(const NarrowBand& band, const OperatorSetup& setup);
void extend_speeds(const NarrowBand& band, std::vector<float>& beta_a, std::vector<float>& beta_p);

}  // namespace levelset::evolve::detail
