// apps/mesh_distance.hpp: the one-sided means and their gross part (the reconstruction
// sweep's split of a Chamfer into a fit's inaccuracy and missed or fused parts).
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "apps/mesh_distance.hpp"

using namespace levelset;
using namespace levelset::apps;

namespace {

// Samples on the x axis; the "surface" is the plane x = 0, so each sample's distance is |x|.
std::vector<Vec3d> on_axis(const std::vector<double>& xs) {
  std::vector<Vec3d> out;
  for (const double x : xs) out.push_back({x, 0.0, 0.0});
  return out;
}

double to_plane(const Vec3d& p) { return std::abs(p.x); }

}  // namespace

TEST(SurfaceDistance, SplitsOffThePartAboveTheGrossThreshold) {
  const std::vector<Vec3d> a = on_axis({0.1, -0.2, 0.3, 5.0}), b = on_axis({0.5, -2.0});
  const SurfaceDistance d = surface_distance(a, to_plane, b, to_plane, {}, 1.0);
  EXPECT_NEAR(d.a_to_b.mean, 5.6 / 4, 1e-12);
  EXPECT_NEAR(d.a_to_b.gross_mean, 5.0 / 4, 1e-12);  // only the 5.0 lies above 1
  EXPECT_NEAR(d.b_to_a.mean, 2.5 / 2, 1e-12);
  EXPECT_NEAR(d.b_to_a.gross_mean, 2.0 / 2, 1e-12);
  EXPECT_NEAR(d.chamfer, 0.5 * (1.4 + 1.25), 1e-12);
  EXPECT_NEAR(d.gross, 0.5 * (1.25 + 1.0), 1e-12);
  EXPECT_DOUBLE_EQ(d.hausdorff, 5.0);
}

TEST(SurfaceDistance, HasNoGrossPartWithoutAThreshold) {
  const std::vector<Vec3d> a = on_axis({0.1, 50.0});
  const SurfaceDistance d = surface_distance(a, to_plane, a, to_plane);
  EXPECT_NEAR(d.chamfer, 25.05, 1e-12);
  EXPECT_EQ(d.gross, 0.0);
  // A distance equal to the threshold is not above it.
  EXPECT_EQ(distances_to(a, to_plane, {}, 50.0).gross_mean, 0.0);
  EXPECT_NEAR(distances_to(a, to_plane, {}, 49.0).gross_mean, 25.0, 1e-12);
}
