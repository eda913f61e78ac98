#include "apps/mesh_distance.hpp"

#include <algorithm>
#include <cmath>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "core/error.hpp"
#include "geometry/point_triangle.hpp"

namespace levelset::apps {

MeshDistance::MeshDistance(const TriangleMesh& mesh) : mesh_(&mesh) {
  if (mesh.triangles.empty()) throw Error(ErrorCode::InvalidArgument, "mesh distance", "the mesh has no triangles");
  std::vector<Vec3d> centres(mesh.triangles.size());
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    const auto& tri = mesh.triangles[t];
    for (std::uint32_t v : tri)
      if (v >= mesh.vertices.size()) throw Error(ErrorCode::InvalidArgument, "mesh distance", "vertex index out of range");
    const Vec3d c = (mesh.vertices[tri[0]] + mesh.vertices[tri[1]] + mesh.vertices[tri[2]]) / 3.0;
    centres[t] = c;
    for (std::uint32_t v : tri) reach_ = std::max(reach_, length(mesh.vertices[v] - c));
  }
  centroids_ = std::make_unique<PointIndex>(centres);
}

double MeshDistance::distance(const Vec3d& p) const {
  auto to_triangle = [&](std::uint32_t t) {
    const auto& tri = mesh_->triangles[t];
    return closest_point_on_triangle(p, mesh_->vertices[tri[0]], mesh_->vertices[tri[1]], mesh_->vertices[tri[2]])
        .distance_squared;
  };
  double best = to_triangle(centroids_->nearest(p).index);
  std::vector<std::pair<std::uint32_t, double>> candidates;
  centroids_->within(p, std::sqrt(best) + reach_, candidates);
  for (const auto& c : candidates) best = std::min(best, to_triangle(c.first));
  return std::sqrt(best);
}

OneSidedDistance distances_to(const std::vector<Vec3d>& samples, const std::function<double(const Vec3d&)>& distance,
                              const ProgressHook& progress, double gross) {
  std::vector<double> d(samples.size());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, samples.size(), 256), [&](const tbb::blocked_range<std::size_t>& r) {
    progress.check("surface distance");
    for (std::size_t i = r.begin(); i != r.end(); ++i) d[i] = std::abs(distance(samples[i]));
  });
  OneSidedDistance o;
  double sum = 0.0, sum2 = 0.0, sum_gross = 0.0;
  for (double v : d) {
    sum += v;
    sum2 += v * v;
    if (v > gross) sum_gross += v;
    o.max = std::max(o.max, v);
  }
  if (!d.empty()) {
    o.mean = sum / double(d.size());
    o.rms = std::sqrt(sum2 / double(d.size()));
    o.gross_mean = sum_gross / double(d.size());
  }
  return o;
}

SurfaceDistance surface_distance(const std::vector<Vec3d>& a_samples, const std::function<double(const Vec3d&)>& b_distance,
                                 const std::vector<Vec3d>& b_samples, const std::function<double(const Vec3d&)>& a_distance,
                                 const ProgressHook& progress, double gross) {
  SurfaceDistance s;
  s.a_to_b = distances_to(a_samples, b_distance, progress, gross);
  s.b_to_a = distances_to(b_samples, a_distance, progress, gross);
  s.gross = 0.5 * (s.a_to_b.gross_mean + s.b_to_a.gross_mean);
  s.chamfer = 0.5 * (s.a_to_b.mean + s.b_to_a.mean);
  s.hausdorff = std::max(s.a_to_b.max, s.b_to_a.max);
  return s;
}

}  // namespace levelset::apps
