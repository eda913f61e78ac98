// surface_coverage (apps/surface_coverage.hpp): the share of points near a band's zero level,
// against a sphere's exact band: points on the sphere count, points 5 voxels off do not, a box
// leaves points out, and bad options are typed errors.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "apps/surface_coverage.hpp"
#include "core/error.hpp"
#include "grid/build_from_sdf.hpp"

namespace levelset::apps {
namespace {

TEST(SurfaceCoverage, PointsOnTheSurfaceCountAndPointsOffItDoNot) {
  const double h = 0.05;
  SdfBuildOptions b;
  b.frame = GridFrame{h, Vec3d{0, 0, 0}, 3.0};
  BBox box;
  box.min = {-1.5, -1.5, -1.5};
  box.max = {1.5, 1.5, 1.5};
  const NarrowBand sphere = build_from_sdf([](const Vec3d& p) { return length(p) - 1.0; }, box, b).band;
  std::vector<Vec3d> points;
  for (int i = 0; i < 400; ++i) {  // a Fibonacci sphere: 200 on the surface, then 200 off it
    const double z = 1.0 - 2.0 * (i % 200 + 0.5) / 200.0, r = std::sqrt(1.0 - z * z);
    const double a = i * std::numbers::pi * (3.0 - std::sqrt(5.0));
    const double radius = i < 200 ? 1.0 : (i < 300 ? 1.0 + 5 * h : 1.0 - 5 * h);
    points.push_back(Vec3d{r * std::cos(a), r * std::sin(a), z} * radius);
  }
  SurfaceCoverageOptions o;
  o.distance = 2 * h;
  const SurfaceCoverageResult all = surface_coverage(sphere, points, o);
  EXPECT_EQ(all.tested, 400u);
  EXPECT_DOUBLE_EQ(all.fraction, 0.5);
  // Every second point (samples = 200): the stride keeps the same half.
  o.samples = 200;
  EXPECT_DOUBLE_EQ(surface_coverage(sphere, points, o).fraction, 0.5);
  // Only the points above z = 0.5 count.
  o.samples = 10000;
  BBox top;
  top.min = {-2, -2, 0.5};
  top.max = {2, 2, 2};
  o.within = top;
  const SurfaceCoverageResult upper = surface_coverage(sphere, points, o);
  EXPECT_GT(upper.tested, 0u);
  EXPECT_LT(upper.tested, 400u);
  // No points: nothing is missed.
  EXPECT_EQ(surface_coverage(sphere, std::vector<Vec3d>{}, o).fraction, 1.0);
  for (double bad : {0.0, -1.0, std::nan("")}) {
    o.distance = bad;
    EXPECT_THROW(surface_coverage(sphere, points, o), Error);
  }
}

}  // namespace
}  // namespace levelset::apps
