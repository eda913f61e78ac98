// The coarse flow's clean-up (reconstruction_parts.hpp drop_unsupported_components): a speck,
// a voxel held a hair inside while its face neighbours are all outside, is turned even where
// points lie beside it; a small component with depth, and the surface itself, stay.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

#include "apps/reconstruction_parts.hpp"
#include "grid/build_from_sdf.hpp"

namespace levelset::apps::detail {
namespace {

constexpr double kRadius = 0.5;

NarrowBand sphere_band() {
  BBox box;
  box.extend({-kRadius, -kRadius, -kRadius});
  box.extend({kRadius, kRadius, kRadius});
  SdfBuildOptions options;
  options.frame = frame_for_resolution(box, 64, 3.0);
  return build_from_sdf([](const Vec3d& p) { return length(p) - kRadius; }, box, options).band;
}

// Points on the sphere (a Fibonacci spiral) and `extra`.
std::vector<Vec3d> sphere_points(const std::vector<Vec3d>& extra) {
  std::vector<Vec3d> points;
  const int n = 4000;
  for (int i = 0; i < n; ++i) {
    const double z = 1.0 - 2.0 * (i + 0.5) / n, r = std::sqrt(1.0 - z * z);
    const double phi = i * std::numbers::pi * (3.0 - std::sqrt(5.0));
    points.push_back(Vec3d{r * std::cos(phi), r * std::sin(phi), z} * kRadius);
  }
  points.insert(points.end(), extra.begin(), extra.end());
  return points;
}

// The voxel on the +x axis about 1.6 voxels outside the sphere.
Coord outside_on_x(const NarrowBand& band) {
  const double h = band.voxel_size();
  return Coord{int(std::lround((kRadius + 1.6 * h - band.origin().x) / h)),
               int(std::lround(-band.origin().y / h)), int(std::lround(-band.origin().z / h))};
}

int inside_face_neighbours(const NarrowBand& band, const Coord& c) {
  const Coord steps[6] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  int n = 0;
  for (const Coord& s : steps) n += band.is_inside(c + s) ? 1 : 0;
  return n;
}

TEST(ReconstructionSpecks, AShallowVoxelAmongOutsideNeighboursIsTurnedBesideItsPoints) {
  NarrowBand band = sphere_band();
  const double h = band.voxel_size();
  const Coord c = outside_on_x(band);
  ASSERT_TRUE(band.value(c).has_value());
  ASSERT_GT(*band.value(c), 1.0 * h);
  band.set_value(c, float(-1e-3 * h));  // what a refused flip holds
  ASSERT_EQ(inside_face_neighbours(band, c), 0);
  const PointIndex index(sphere_points({band.world(c)}));  // a point on the speck: supported
  const double before_inside = double(
      std::count_if(band.values().begin(), band.values().end(), [](float v) { return v < 0.0f; }));
  EXPECT_EQ(drop_unsupported_components(band, index, 1.5 * h, {}), 1u);
  EXPECT_FALSE(band.is_inside(c));
  const double after_inside = double(
      std::count_if(band.values().begin(), band.values().end(), [](float v) { return v < 0.0f; }));
  EXPECT_EQ(after_inside, before_inside - 1.0);  // the sphere's own voxels all stay
}

TEST(ReconstructionSpecks, ASmallComponentWithDepthBesideItsPointsStays) {
  NarrowBand band = sphere_band();
  const double h = band.voxel_size();
  const Coord c = outside_on_x(band);
  // A 1x2x2 block half a voxel deep: small, but more than a hair inside.
  const Coord block[4] = {c, c + Coord{0, 1, 0}, c + Coord{0, 0, 1}, c + Coord{0, 1, 1}};
  for (const Coord& b : block) {
    ASSERT_TRUE(band.value(b).has_value());
    band.set_value(b, float(-0.5 * h));
  }
  const PointIndex index(sphere_points({band.world(c)}));
  EXPECT_EQ(drop_unsupported_components(band, index, 1.5 * h, {}), 0u);
  for (const Coord& b : block) EXPECT_TRUE(band.is_inside(b));
}

TEST(ReconstructionSpecks, AComponentAwayFromThePointsIsTurnedWhateverItsDepth) {
  NarrowBand band = sphere_band();
  const double h = band.voxel_size();
  const Coord c = outside_on_x(band);
  band.set_value(c, float(-0.5 * h));
  const PointIndex index(sphere_points({}));
  ASSERT_GT(index.nearest(band.world(c)).distance, 1.5 * h);  // unsupported
  EXPECT_EQ(drop_unsupported_components(band, index, 1.5 * h, {}), 1u);
  EXPECT_FALSE(band.is_inside(c));
}

}  // namespace
}  // namespace levelset::apps::detail
