// Cost (slowness) fields and obstacles for the fast march: turns the user's description of
// the medium into one dense array of node costs over a DenseGrid.
//
// Cost c(x) > 0 is the travel time per world unit (c = 1/F for a front speed F); the
// arrival time T solves |grad T| = c. An obstacle node has c = +inf (never entered).
// Inputs (CostField, the first one given wins):
//   values   a dense array in grid order (x fastest), one cost per node;
//   function c(world point), called concurrently from worker threads;
//   formula  text over x y z (world coordinates) and h (voxel size) plus named constants
//            (formula/formula.hpp), evaluated in single precision;
//   uniform  the constant cost when none of the above is given (default 1).
//   Values must be > 0 and not NaN; +inf marks a node blocked.
// Obstacles (both may be given; a node blocked by either is blocked):
//   band     a NarrowBand, inside (the trilinearly sampled value < clearance) is blocked;
//            outside its band only the sign is known, so |clearance| must stay below the
//            band's background (W h) and the band's sign decides there;
//   mask     a dense array in grid order, nonzero = blocked.
// Output: CostGrid (the node costs, +inf where blocked, and counts).
// Cost: O(nodes) evaluations (a formula runs over rows of up to 512 nodes at once); the
//   band adds 8 accessor reads per node. Memory: 8 bytes per node.
// Threading: TBB over z-slices; results are identical for any thread count.
// Errors (thrown): Error{InvalidArgument} when a dense array's size differs from the grid's,
//   a cost is <= 0, the formula reads variables other than x y z h, or the clearance is not
//   within the band's background; Error{NonFinite} for a NaN cost (naming the node);
//   Error{ParseError/LimitExceeded} from the formula compiler; Error{Cancelled}.
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "apps/dense_grid.hpp"
#include "core/progress.hpp"
#include "grid/narrow_band.hpp"

namespace levelset::apps {

struct CostField {
  std::vector<double> values;                    // dense, grid order
  std::function<double(const Vec3d&)> function;  // c(world point)
  std::string formula;                           // over x y z h
  std::map<std::string, double, std::less<>> constants;  // named constants for the formula
  double uniform = 1.0;
};

struct Obstacles {
  const NarrowBand* band = nullptr;  // not owned; must outlive the call
  double clearance = 0.0;            // world units: blocked where the band value < clearance
  std::vector<std::uint8_t> mask;    // dense, grid order, nonzero = blocked
};

struct CostGrid {
  DenseGrid grid;
  std::vector<double> cost;          // per node, +inf = blocked
  std::uint64_t blocked = 0;         // nodes with cost = +inf
  double min_cost = 0, max_cost = 0; // over the free nodes (0 when none is free)
  // The medium's exact cost at a world point (the CostField's function or formula), empty
  // for dense values and uniform costs. Thread-safe.
  std::function<double(const Vec3d&)> pointwise;
};

CostGrid build_cost_grid(const DenseGrid& grid, const CostField& cost, const Obstacles& obstacles,
                         const ProgressHook& progress = {});

// The cost at a world point inside the grid: +inf when the nearest node is blocked (so points
// inside obstacles read as blocked), else costs.pointwise(p) when set (seeds between nodes
// see the exact medium), else the trilinear interpolation over the finite corner costs.
// Error{InvalidArgument} for a point outside the grid.
double cost_at(const CostGrid& costs, const Vec3d& p);

}  // namespace levelset::apps
