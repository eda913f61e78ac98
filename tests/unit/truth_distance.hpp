// Test helper: how far the true surface lies from a reconstruction, on average (large where a
// gap or hole of the truth is filled, or a part is missing).
#pragma once

#include <vector>

#include "apps/mesh_distance.hpp"
#include "apps/sample_points.hpp"
#include "io/triangle_mesh.hpp"

namespace levelset::test {

// The mean distance from 50k area samples of `truth` (seed 7) to `mesh`.
inline double mean_distance_from(const TriangleMesh& truth, const TriangleMesh& mesh) {
  apps::SurfaceSampleOptions ts;
  ts.count = 50000;
  ts.seed = 7;
  const apps::MeshDistance d(mesh);
  double sum = 0.0;
  const std::vector<Vec3d> samples = apps::sample_mesh_surface(truth, ts);
  for (const Vec3d& p : samples) sum += d.distance(p);
  return sum / double(samples.size());
}

}  // namespace levelset::test
