// point_extent (apps/point_extent.hpp): the box of a cloud without its isolated points. A
// sphere's samples with scattered far outliers give the sphere's box and count the outliers;
// a clump of more than k points far away is data; a thinly sampled tail next to the data stays
// inside; a clean cloud keeps its raw box. And reconstruct_surface on the sphere with
// outliers gives the sphere (before, the grid spanned the outliers and the result was empty).
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include "apps/point_extent.hpp"
#include "apps/reconstruction.hpp"
#include "apps/sample_points.hpp"
#include "geometry/analytic_shapes.hpp"

namespace levelset::apps {
namespace {

std::vector<Vec3d> sphere_points(std::size_t count, unsigned seed) {
  SurfaceSampleOptions s;
  s.count = count;
  s.seed = seed;
  return sample_shape_surface(*make_sphere({0, 0, 0}, 1.0), s);
}

void expect_unit_box(const BBox& box, double tolerance) {
  for (int a = 0; a < 3; ++a) {
    EXPECT_NEAR(box.min[a], -1.0, tolerance) << "axis " << a;
    EXPECT_NEAR(box.max[a], 1.0, tolerance) << "axis " << a;
  }
}

TEST(PointExtent, ScatteredOutliersAreLeftOut) {
  std::vector<Vec3d> p = sphere_points(10000, 1);
  std::mt19937_64 rng(2);
  std::uniform_real_distribution<double> far(-1000.0, 1000.0);
  for (int i = 0; i < 40; ++i) p.push_back({far(rng), far(rng), far(rng)});
  const PointIndex index(p);
  const PointExtentResult r = point_extent(index);
  EXPECT_EQ(r.isolated, 40u);
  expect_unit_box(r.box, 0.02);
}

TEST(PointExtent, CleanCloudsAndClumpsKeepTheirBox) {
  const PointIndex clean(sphere_points(10000, 3));
  const PointExtentResult c = point_extent(clean);
  EXPECT_EQ(c.isolated, 0u);
  expect_unit_box(c.box, 0.02);
  // Twenty points together far away: a second part of the data, not outliers.
  std::vector<Vec3d> p = sphere_points(10000, 4);
  for (int i = 0; i < 20; ++i) p.push_back({50.0 + 0.01 * i, 0.0, 0.0});
  const PointExtentResult clump = point_extent(PointIndex(p));
  EXPECT_EQ(clump.isolated, 0u);
  EXPECT_NEAR(clump.box.max.x, 50.19, 1e-9);
  // A thin tail leaving the sphere, sampled ever more sparsely: each point is isolated by
  // the k-nearest rule, but lies within reach of the data, so the box takes it.
  std::vector<Vec3d> t = sphere_points(10000, 5);
  double x = 1.0;
  for (int i = 0; i < 12; ++i) t.push_back({x += 0.02 * (i + 1), 0.0, 0.0});
  const PointExtentResult tail = point_extent(PointIndex(t));
  EXPECT_EQ(tail.isolated, 0u);
  EXPECT_NEAR(tail.box.max.x, x, 1e-9);
}

TEST(PointExtent, ReconstructionIgnoresScatteredOutliers) {
  std::vector<Vec3d> p = sphere_points(8000, 6);
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> far(-1000.0, 1000.0);
  for (int i = 0; i < 30; ++i) p.push_back({far(rng), far(rng), far(rng)});
  ReconstructionOptions o;
  o.resolution = 64;
  const ReconstructionResult r = reconstruct_surface(p, o);
  EXPECT_EQ(r.isolated_points, 30u);
  EXPECT_TRUE(r.measures.watertight);
  EXPECT_EQ(r.measures.genus, 0.0);
  EXPECT_NEAR(r.measures.area, 4.0 * std::numbers::pi, 0.05 * 4.0 * std::numbers::pi);
}

}  // namespace
}  // namespace levelset::apps
