// Exact distances from points to a triangle mesh, and the symmetric Chamfer / Hausdorff
// distances between two surfaces: the accuracy measure of the reconstruction (tests, bench).
//
// MeshDistance: a kd-tree over the triangles' centroids (apps/point_distance.hpp). A query
//   takes the exact distance D0 to the triangle of the nearest centroid (an upper bound), then
//   the exact point-triangle distance (geometry/point_triangle.hpp) to every triangle whose
//   centroid lies within D0 + r_max (r_max = the largest centroid-vertex distance of any
//   triangle; no closer triangle can lie outside that ball), so the result is exact.
//   Cost per query: O(log F + candidates). Thread-safe queries.
// surface_distance(a_samples, b, b_samples, a): one-sided distances of samples of surface A to
//   mesh B and of samples of B to mesh A: chamfer = (mean_AB + mean_BA) / 2, hausdorff = max
//   of both maxima; with a threshold `gross`, the part of each mean carried by distances above
//   it (missed parts, fused gaps: the errors a local fit cannot cause) apart, and `gross` the
//   same split of the Chamfer. TBB over queries, deterministic (sums in index order).
// Errors: Error{InvalidArgument} for a mesh without triangles or an index out of range.
#pragma once

#include <functional>
#include <limits>
#include <memory>
#include <vector>

#include "apps/point_distance.hpp"
#include "core/progress.hpp"
#include "io/triangle_mesh.hpp"

namespace levelset::apps {

class MeshDistance {
 public:
  explicit MeshDistance(const TriangleMesh& mesh);
  double distance(const Vec3d& p) const;

 private:
  const TriangleMesh* mesh_;
  std::unique_ptr<PointIndex> centroids_;
  double reach_ = 0.0;
};

struct OneSidedDistance {
  double mean = 0.0, rms = 0.0, max = 0.0;
  double gross_mean = 0.0;  // sum of the distances above the gross threshold / all samples (a part of mean)
};

// Distances of the samples to a surface given by its distance function (thread-safe).
// progress: checked per chunk of samples (Error{Cancelled}).
OneSidedDistance distances_to(const std::vector<Vec3d>& samples, const std::function<double(const Vec3d&)>& distance,
                              const ProgressHook& progress = {},
                              double gross = std::numeric_limits<double>::infinity());

struct SurfaceDistance {
  OneSidedDistance a_to_b, b_to_a;
  double chamfer = 0.0;         // (a_to_b.mean + b_to_a.mean) / 2
  double hausdorff = 0.0;       // max of both maxima
  double gross = 0.0;           // (a_to_b.gross_mean + b_to_a.gross_mean) / 2: the part of chamfer above the threshold
};

SurfaceDistance surface_distance(const std::vector<Vec3d>& a_samples, const std::function<double(const Vec3d&)>& b_distance,
                                 const std::vector<Vec3d>& b_samples, const std::function<double(const Vec3d&)>& a_distance,
                                 const ProgressHook& progress = {},
                                 double gross = std::numeric_limits<double>::infinity());

}  // namespace levelset::apps
