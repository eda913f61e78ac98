// fast_marching: first arrival times |grad T| = c(x) (c = 1/F) from point seeds on a dense
// grid, with obstacles; the label of the seed that arrives first (thesis 2.3.3, 3.5, 3.6).
//
// Inputs: FastMarchingOptions below: the grid (apps/dense_grid.hpp), seeds (world points,
//   anywhere inside the grid, not on grid nodes necessarily, each with a label >= 0), the
//   medium (apps/cost_field.hpp: cost and obstacles).
// Method (Sethian's Fast Marching Method):
//   1. Seeds: every free node within seed_radius voxels of a seed (and at least the 8
//      corners of the seed's cell) is fixed at the travel time along the straight segment,
//      |x - s| * Simpson(c(s), c(mid), c(x)), exact for uniform cost and O(|x - s|^5 c'')
//      otherwise; the smallest over seeds wins, with its label. Straight segments are not
//      checked against obstacles (they are at most seed_radius voxels long).
//   2. March: a binary min-heap of trial nodes; the smallest is accepted and its six
//      neighbours updated. order 2: per axis the upwind (smaller) accepted neighbour m1 and,
//      when the next node on that side is accepted with m2 <= m1, the second-order one-sided
//      difference (3T - 4 m1 + m2) / 2h; the quadratic sum_a alpha_a (T - beta_a)^2 =
//      (h c)^2 is solved over the axes in increasing beta while they stay upwind; when a
//      second-order system has no admissible root the first-order update is used
//      (counted in first_order_fallbacks). order 1: Godunov's first-order update.
//      A node takes the label of its smallest upwind accepted neighbour.
//   3. Blocked nodes (cost +inf) are never entered; nodes cut off by obstacles stay +inf
//      with label -1.
// Output: FastMarchingResult: T per node (world time units = cost x length), labels.
// Accuracy: order 2 converges at second order when the seed layer keeps a fixed world
//   radius (seed_radius = r / h; measured error ratios 4.2 and 4.6 per halving of h on the
//   cost 1/y field); with a fixed radius in voxels the point source limits it to about
//   first order (ratios ~1.7-1.9), with errors still ~0.3% at 30 voxels from the seed.
//   order 1 converges at first order (ratio 2.0).
// Stopping: at the first node with T > stop_time (it and all trial nodes go back to +inf,
//   label -1; result.complete = false). With stop_targets (world points inside the grid),
//   stop_time drops to T + 3 h max_cost once every free node of every target's cell is
//   accepted: enough for trace_path to the targets (path planning stops early this way).
// Cost: O(N log N) for N reached nodes, plus the cost grid (apps/cost_field.hpp).
// Memory: about 25 bytes per node while marching (T 8, cost 8, state / heap slot 4,
//   label 4, blocked 1) plus 16 bytes per trial node in the heap; the result keeps T,
//   labels and the blocked mask (13 bytes per node).
// Threading: the march itself is sequential (the heap order is inherently serial); the cost
//   grid is built with TBB. Results are identical for any thread count.
// Progress: stages "cost" and "march" (fraction of free nodes accepted); cancel is checked
//   every 16384 accepted nodes (Error{Cancelled}).
// Errors (thrown): Error{InvalidArgument} for no seeds, a seed outside the grid or on a
//   blocked point, a negative label, order not 1 or 2, seed_radius outside [0, 16], NaN
//   stop_time, a stop target outside the grid; Error{NonFinite} for a non-finite seed or target; Error{LimitExceeded} for a grid above
//   max_voxels or more than 2^20 seeds; the cost grid's errors.
#pragma once

#include <cstdint>
#include <limits>
#include <vector>

#include "apps/cost_field.hpp"
#include "apps/dense_grid.hpp"
#include "core/progress.hpp"

namespace levelset::apps {

struct Seed {
  Vec3d position;
  std::int32_t label = 0;  // >= 0; -1 in results means "not reached"
};

struct FastMarchingOptions {
  DenseGrid grid;
  std::vector<Seed> seeds;
  CostField cost;
  Obstacles obstacles;
  int order = 2;                 // 1 or 2
  double seed_radius = 2.0;      // voxels, in [0, 16]
  double stop_time = std::numeric_limits<double>::infinity();
  std::vector<Vec3d> stop_targets;  // see Stopping above; at most 2^20
  std::uint64_t max_voxels = kDefaultMaxGridVoxels;
  ProgressHook progress;
};

struct FastMarchingResult {
  DenseGrid grid;
  std::vector<double> time;            // per node; +inf = not reached (or blocked)
  std::vector<std::int32_t> label;     // per node; -1 = not reached
  std::vector<std::uint8_t> blocked;   // per node; 1 = obstacle (cost +inf)
  std::vector<Seed> seeds;             // as given
  std::uint64_t accepted = 0;          // nodes accepted by the march (seed layer included)
  std::uint64_t blocked_count = 0;
  std::uint64_t seed_nodes = 0;        // nodes fixed by the seed initialisation
  std::uint64_t second_order_updates = 0, first_order_updates = 0, first_order_fallbacks = 0;
  bool complete = true;                // false when stop_time cut the march short
  double min_cost = 0, max_cost = 0;   // over free nodes
  double seconds_cost = 0, seconds_march = 0;
};

FastMarchingResult fast_marching(const FastMarchingOptions& options);

}  // namespace levelset::apps
