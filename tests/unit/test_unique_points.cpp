// unique_points (apps/unique_points.hpp): copies and points within the tolerance's cell merge,
// distinct points stay in their order; and reconstruct_surface on a cloud listed three times
// gives the same surface as the cloud given once (before, the copies read as a denser sampling,
// the resolution rose to 512, and where every fit saw a third of its neighbours a sphere came
// out as scraps of genus 26 or 30).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>
#include <random>
#include <vector>

#include "apps/reconstruction.hpp"
#include "apps/unique_points.hpp"
#include "core/error.hpp"

namespace levelset::apps {
namespace {

TEST(UniquePoints, CopiesMergeAndTheRestKeepsItsOrder) {
  const std::vector<Vec3d> p{{1, 2, 3}, {0, 0, 0}, {1, 2, 3}, {-0.0, 0, 0}, {4, 5, 6}, {1, 2, 3.0000001}};
  const UniquePointsResult exact = unique_points(p);
  EXPECT_EQ(exact.merged, 2u);  // the second {1,2,3} and -0 == +0
  ASSERT_EQ(exact.points.size(), 4u);
  EXPECT_EQ(exact.points[0], (Vec3d{1, 2, 3}));
  EXPECT_EQ(exact.points[1], (Vec3d{0, 0, 0}));
  EXPECT_EQ(exact.points[2], (Vec3d{4, 5, 6}));
  EXPECT_EQ(exact.points[3], (Vec3d{1, 2, 3.0000001}));
  // With a tolerance of 1e-3 the jittered copy shares {1,2,3}'s cell.
  UniquePointsOptions o;
  o.tolerance = 1e-3;
  const UniquePointsResult near = unique_points(p, o);
  EXPECT_EQ(near.merged, 3u);
  EXPECT_EQ(near.points.size(), 3u);
}

TEST(UniquePoints, DistinctPointsAndHugeCoordinatesStay) {
  std::vector<Vec3d> p;
  for (int i = 0; i < 1000; ++i) p.push_back({0.001 * i, std::sin(double(i)), 1e300 * (i % 2)});
  UniquePointsOptions o;
  o.tolerance = 1e-6;  // 1e300 / 1e-6 overflows the cell index: compared exactly there
  const UniquePointsResult r = unique_points(p, o);
  EXPECT_EQ(r.merged, 0u);
  EXPECT_EQ(r.points, p);
}

TEST(UniquePoints, BadToleranceIsATypedError) {
  for (double t : {-1.0, std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity()}) {
    UniquePointsOptions o;
    o.tolerance = t;
    try {
      unique_points({{0, 0, 0}}, o);
      ADD_FAILURE() << "no error for tolerance " << t;
    } catch (const Error& e) {
      EXPECT_EQ(e.code(), ErrorCode::InvalidArgument);
    }
  }
}

TEST(UniquePoints, ReconstructionOfACloudListedThreeTimesIsTheSurface) {
  // 5000 independent uniform points on the unit sphere (normalised Gaussian triples).
  std::mt19937_64 rng(4);
  std::normal_distribution<double> g(0, 1);
  std::vector<Vec3d> once(5000);
  for (Vec3d& q : once) {
    const Vec3d v{g(rng), g(rng), g(rng)};
    q = v / length(v);
  }
  std::vector<Vec3d> thrice;
  for (int copy = 0; copy < 3; ++copy) thrice.insert(thrice.end(), once.begin(), once.end());
  const ReconstructionResult r = reconstruct_surface(thrice, {});  // resolution from the data
  EXPECT_EQ(r.duplicate_points, 10000u);
  // The copies change nothing: the same resolution (the copies read as a sampling sqrt(3)
  // times denser: resolution 360 instead of 174) and the same band as the points given once.
  const ReconstructionResult single = reconstruct_surface(once, {});
  EXPECT_EQ(single.duplicate_points, 0u);
  EXPECT_EQ(r.resolution, single.resolution);
  EXPECT_TRUE(r.band.identical(single.band));
  EXPECT_TRUE(r.measures.watertight);
  EXPECT_EQ(r.measures.genus, 0.0);
  EXPECT_EQ(r.measures.components, 1u);
  EXPECT_NEAR(r.measures.area, 4.0 * std::numbers::pi, 0.02 * 4.0 * std::numbers::pi);
  // Copies of three points are three points.
  std::vector<Vec3d> few;
  for (int copy = 0; copy < 10; ++copy) few.insert(few.end(), {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}});
  try {
    reconstruct_surface(few, {});
    ADD_FAILURE() << "no error for three distinct points";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::InvalidArgument);
    EXPECT_NE(std::string(e.what()).find("distinct"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace levelset::apps
