// Path planning (thesis 3.6): the cheapest path from a start to a goal through a medium
// with cost c(x) (time per world unit) and obstacles, by fast marching from the start and
// back-tracing down the arrival time field from the goal.
//
// trace_path: from the goal, follow -grad T / |grad T| (a unit-speed curve in world units)
//   with Heun's method (rk_order 2) or classical RK4 (rk_order 4), step `step` voxels, until
//   the point is within stop_distance voxels of a seed; the seed itself ends the polyline.
//   grad T at a node: central differences; one-sided where a neighbour is unreached or
//   blocked, and towards the smaller neighbour where the node is a local maximum along an
//   axis (a shock, where two fronts meet); between nodes the trilinear blend of the node
//   gradients over the corners with finite T. Points are clamped into the grid.
//   arrival_time: T at the goal, trilinearly interpolated over the finite corners (exact at
//   nodes). length: the polyline's length (world units).
// plan_path: fast_marching (apps/fast_marching.hpp) from the start, stopped soon after the
//   front passes the goal (unless keep_field asks for the whole field), then trace_path.
// Accuracy (tests/unit/test_path_planning.cpp, order 2, step 0.5 voxels): length and time
//   within 0.5% for paths of 30 to 200 voxels: straight lines, the circular geodesics of
//   cost 1/y, the path around a sphere. Obstacles are resolved to the node (a node is free
//   or blocked), so their part of the error is first order in h: about +0.5% around a
//   sphere of 50 voxels radius. At sharp convex obstacle corners the trace blends the
//   gradients of both sides and may cut the corner by up to about a voxel: the length then
//   falls below the arrival time by O(h) (the time stays accurate). Inside obstacles the
//   trace reads ghost times (2 layers, continued with twice the largest cost), which push
//   it back out. A goal exactly on a shock (equally fast around both sides of an obstacle)
//   blends both sides' gradients there; the trace then leaves along whichever side the
//   blend favours, or stalls.
// Cost: the march, O(N log N); the ghost layers one O(N) pass; the trace O(length / step)
//   with 8 node gradients per stage.
// Memory: the march's (about 25 bytes per node), then 8 bytes per node for the trace's copy
//   of T with ghosts; keep_field keeps T, labels and the blocked mask in the result.
// Threading: as fast_marching (sequential march, parallel cost grid); the trace is serial.
//   Results are identical for any thread count.
// Errors (thrown): Error{InvalidArgument} for a goal outside the grid, in an obstacle or
//   unreachable (T = +inf: obstacles cut it off), step not in (0, 1], stop_distance not in
//   [step, 8], rk_order not 2 or 4, or a trace that stalls (no decrease of T over 64 steps,
//   or max_steps reached); Error{NonFinite} for a non-finite start or goal; fast_marching's
//   errors (start outside the grid or in an obstacle, sizes); Error{Cancelled}.
#pragma once

#include <cstdint>
#include <vector>

#include "apps/fast_marching.hpp"

namespace levelset::apps {

struct TraceOptions {
  double step = 0.5;           // voxels, in (0, 1]
  double stop_distance = 1.0;  // voxels, in [step, 8]
  int rk_order = 2;            // 2: Heun, 4: classical Runge-Kutta
  std::uint64_t max_steps = 0; // 0: 4 x the grid's node count, at most 10^8
  ProgressHook progress;       // cancel checked every 1024 steps
};

struct TraceResult {
  std::vector<Vec3d> points;   // the seed reached first, the goal last (world units)
  double length = 0;           // world units
  double arrival_time = 0;     // T at the goal
  std::size_t seed_index = 0;  // which seed of the field the path reached
  std::uint64_t steps = 0;
};

TraceResult trace_path(const FastMarchingResult& field, const Vec3d& goal, const TraceOptions& options = {});

// T at a world point inside the field's grid, trilinear over the corners with finite T;
// +inf when none is finite. Error{InvalidArgument} outside the grid.
double sample_time(const FastMarchingResult& field, const Vec3d& p);

struct PathOptions {
  DenseGrid grid;
  Vec3d start{}, goal{};
  CostField cost;
  Obstacles obstacles;
  int order = 2;               // fast marching order, 1 or 2
  double seed_radius = 2.0;    // voxels, see FastMarchingOptions
  std::uint64_t max_voxels = kDefaultMaxGridVoxels;
  TraceOptions trace;          // its progress hook is replaced by `progress`
  bool keep_field = false;     // march the whole grid and keep the arrival times in the result
  ProgressHook progress;
};

struct PathResult {
  std::vector<Vec3d> points;   // start first, goal last
  double length = 0;           // world units
  double arrival_time = 0;     // travel time start -> goal (cost x length units)
  std::uint64_t steps = 0;     // trace steps
  std::uint64_t accepted = 0, blocked = 0;  // march counts
  std::uint64_t first_order_fallbacks = 0;
  FastMarchingResult field;    // only with keep_field
  double seconds_cost = 0, seconds_march = 0, seconds_trace = 0;
};

PathResult plan_path(const PathOptions& options);

}  // namespace levelset::apps
