// project_to_planes: each point moved onto the least-squares plane of its k nearest points
// (itself included): normal noise averaged over the neighbourhood, for queries that read
// "how far is the nearest sample" and must not see the noise's scatter (the carving's
// clearance under noise, reconstruction_carve.cpp).
//
// Inputs: a PointIndex over the points (world units); ProjectToPlanesOptions (k in [4, 64]).
// Method: per point, the centroid c and the smallest eigenvector n of its k nearest points'
//   covariance (geometry/symmetric_eigen.hpp); the point becomes p - ((p - c).n) n. On a
//   smooth surface that removes all but ~sigma / sqrt(k) of the normal noise and moves clean
//   points by the patch's sagitta (~ r^2 / (2 R), r the k-neighbourhood's radius); where the
//   neighbourhood spans two sheets (a part thinner than r) points would move toward the
//   middle: no point moves farther than max_move (world; 0: no bound), so a caller that
//   knows the noise's sigma keeps the sheets apart by bounding the move by a few sigma.
// Output: ProjectToPlanesResult::points, in the index's order. Cost: O(N k log N), parallel
//   over points (TBB). Threading: reentrant. Errors: Error{InvalidArgument} for k outside
//   [4, 64] or a negative or non-finite max_move; Error{Cancelled} through the hook (checked every
//   1024 points).
#pragma once

#include <vector>

#include "apps/point_distance.hpp"
#include "core/progress.hpp"

namespace levelset::apps {

struct ProjectToPlanesOptions {
  int neighbors = 24;
  double max_move = 0.0;
  ProgressHook progress;
};

struct ProjectToPlanesResult {
  std::vector<Vec3d> points;
};

ProjectToPlanesResult project_to_planes(const PointIndex& index,
                                        const ProjectToPlanesOptions& options = {});

}  // namespace levelset::apps
