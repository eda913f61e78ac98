// point_extent: the bounding box of a point cloud without its isolated points (a scan's far
// outliers), which would otherwise set the extent of every grid built around the cloud: 50
// stray points at 1e6 beside a unit-sized object left a reconstruction of a few triangles.
//
// Inputs: a PointIndex (world units); options.neighbors k and options.factor f.
// Isolated: a point whose k-th nearest other point is farther than f * g, g the sampling gap
//   (sample_gap(index, k, 0.9, 4000): the 90th percentile of that distance over the cloud), so
//   a clump of fewer than k + 1 points far from the rest counts as isolated and a larger one as
//   data.
// Method: only the extremes are tested. When none of the six points on the raw box's faces is
//   isolated (the usual cloud: six k-nearest queries) the box is the raw one; otherwise, per
//   axis, the points sorted by that coordinate are walked from each end past the isolated
//   ones, the box spans the first non-isolated point from each end, and then grows to take
//   every point within f * g of it (repeatedly): a thinly sampled tail of the surface next to
//   the data stays inside, only points far from all data are left out.
// Output: the box, how many isolated points lie outside it, and g. All points isolated (a
//   cloud too sparse for k): the raw box. Cost: O(k log N) usually; O(N log N + m k log N)
//   with m outliers. Threading: serial. Errors: none beyond PointIndex's.
#pragma once

#include <cstdint>

#include "apps/point_distance.hpp"
#include "core/bbox.hpp"

namespace levelset::apps {

struct PointExtentOptions {
  int neighbors = 8;
  double factor = 8.0;
};

struct PointExtentResult {
  BBox box;
  std::uint64_t isolated = 0;  // points outside box
  double gap = 0.0;            // g (world): sample_gap(index, k, 0.9, 4000), also for small clouds
};

PointExtentResult point_extent(const PointIndex& index, const PointExtentOptions& options = {});

}  // namespace levelset::apps
