// estimate_sampling: how densely and how noisily a point cloud samples its surface, measured
// from the points alone (no normals, no mesh): what an automatic reconstruction resolution
// follows from (apps/reconstruction.hpp, resolution 0).
//
// Inputs: a PointIndex over the points (world units); SamplingEstimateOptions.
// Method: over up to `samples` points (every (N / samples)-th: deterministic), the k nearest
//   other points (k = neighbors) give
//   - spacing: sqrt(pi d8^2 / 8) with d8 the median distance to the 8th nearest: the side of
//     the surface area per point (a uniform sampling of density rho has pi d8^2 rho = 8);
//   - noise: the median over the samples of sqrt(lambda_min) of the k points' covariance (the
//     spread of the points normal to their local tangent plane). Clean points on a curved
//     surface still show the patch's sagitta (~ r^2 / (8 R) for a patch of radius r on a
//     surface of radius R), so the estimate is an upper bound of the noise's sigma: read it
//     against spacing (noise / spacing below ~0.1 is clean).
// Output: SamplingEstimate (world units). Cost: O(samples k log N), serial. Threading:
//   reentrant. Clouds of N <= neighbors points use N - 1 neighbours (and the min(8, N - 1)-th
//   nearest for the spacing). Errors: Error{InvalidArgument} for fewer than 4 points or
//   neighbors not in [8, 64]; Error{Cancelled} through the hook.
#pragma once

#include <cstddef>

#include "apps/point_distance.hpp"
#include "core/progress.hpp"

namespace levelset::apps {

struct SamplingEstimateOptions {
  int neighbors = 16;
  std::size_t samples = 2000;
  ProgressHook progress;
};

struct SamplingEstimate {
  double spacing = 0.0;  // world: side of the surface area per point
  double noise = 0.0;    // world: the points' spread normal to the surface (upper bound of sigma)
  std::size_t samples = 0;
};

SamplingEstimate estimate_sampling(const PointIndex& index, const SamplingEstimateOptions& options = {});

}  // namespace levelset::apps
