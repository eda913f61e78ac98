#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <random>
#include <utility>
#include <vector>

#include "distance/rim_cone.hpp"
#include "distance/winding_number.hpp"
#include "distance_test_meshes.hpp"
#include "grid/coord.hpp"

namespace levelset {
namespace {

// The open edges of a mesh (directed edges whose reverse is not used), in triangle order.
std::vector<OpenSegment> rim_segments(const TriangleMesh& m) {
  std::map<std::pair<std::uint32_t, std::uint32_t>, int> uses;
  for (const auto& f : m.triangles)
    for (int k = 0; k < 3; ++k) ++uses[{f[k], f[(k + 1) % 3]}];
  std::vector<OpenSegment> out;
  for (const auto& [edge, count] : uses)
    if (!uses.count({edge.second, edge.first}))
      out.push_back({m.vertices[edge.first], m.vertices[edge.second]});
  return out;
}

// A hemisphere of radius 3 about the middle of the brick [0, 7]^3, tilted off the grid.
TriangleMesh brick_hemisphere() {
  TriangleMesh m = test::hemisphere(6, 24, 3.0);
  const double c = std::cos(0.4), s = std::sin(0.4);
  for (Vec3d& v : m.vertices) v = Vec3d{c * v.x - s * v.z, v.y, s * v.x + c * v.z} + Vec3d{3.5, 3.4, 3.6};
  return m;
}

TEST(RimCone, SurfaceMinusConeIsAnIntegerOffBoth) {
  const TriangleMesh m = brick_hemisphere();
  const std::vector<OpenSegment> rims = rim_segments(m);
  ASSERT_EQ(rims.size(), 24u);
  const auto cone = make_rim_cone(rims, Coord{0, 0, 0}, 8, 4.0, 4.0);
  ASSERT_TRUE(cone.has_value());
  EXPECT_EQ(cone->segments.size(), 24u);
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> U(-2.0, 9.0);
  int fractional = 0;
  double worst = 0.0;
  for (int i = 0; i < 2000; ++i) {
    const Vec3d p{U(rng), U(rng), U(rng)};
    const double difference = winding_number_exact(m, p) - cone_winding(*cone, p);
    worst = std::max(worst, std::abs(difference - std::round(difference)));
    // The continuous parts cancel; what is left is the winding number of a closed surface.
    fractional += std::abs(difference - std::round(difference)) > 1e-9;
  }
  EXPECT_EQ(fractional, 0) << "worst distance from an integer " << worst;
}

TEST(RimCone, BlockEvaluationMatchesTheScalarSum) {
  const TriangleMesh m = brick_hemisphere();
  const auto cone = make_rim_cone(rim_segments(m), Coord{0, 0, 0}, 8, 4.0, 4.0);
  ASSERT_TRUE(cone.has_value());
  for (int s : {8, 4}) {
    const Coord lo = s == 8 ? Coord{0, 0, 0} : Coord{4, 0, 4};
    double block[kBrickVoxels];
    cone_winding_block(*cone, lo, s, block);
    double worst = 0.0;
    for (int k = lo.z; k < lo.z + s; ++k)
      for (int j = lo.y; j < lo.y + s; ++j)
        for (int i = lo.x; i < lo.x + s; ++i) {
          const double exact = cone_winding(*cone, Vec3d{double(i), double(j), double(k)});
          worst = std::max(worst, std::abs(block[local_index(i, j, k)] - exact));
        }
    // 24 segments, each within 2e-8 rad of the exact angle (times 2 / 4 pi).
    EXPECT_LT(worst, 1e-7) << "block size " << s;
  }
}

TEST(RimCone, PartialRimTakesTheSegmentsInReachAndClearsItsApexSegments) {
  // A straight rim along x through the block's middle, from x = -40 to 40 in unit steps.
  std::vector<OpenSegment> rims;
  for (int i = -40; i < 40; ++i)
    rims.push_back({Vec3d{i + 0.25, 3.3, 3.7}, Vec3d{i + 1.25, 3.3, 3.7}});
  const Coord lo{0, 0, 0};
  const auto cone = make_rim_cone(rims, lo, 8, 4.0, 4.0);
  ASSERT_TRUE(cone.has_value());
  // Segments meeting x in [-4, 11]: starts from -5.25 to 10.25.
  EXPECT_EQ(cone->segments.size(), 16u);
  const Vec3d grown_lo{-4, -4, -4}, grown_hi{11, 11, 11};
  for (const Vec3d& end : {cone->segments.front()[0], cone->segments.back()[1]})
    EXPECT_FALSE(segment_meets_box(end, cone->apex, grown_lo, grown_hi));
  // Far from every rim: no cone.
  EXPECT_FALSE(make_rim_cone(rims, Coord{0, 40, 0}, 8, 4.0, 4.0).has_value());
}

TEST(RimCone, ReversedTrianglesCloseTheSurfaceAlongTheRim) {
  const TriangleMesh m = brick_hemisphere();
  const auto cone = make_rim_cone(rim_segments(m), Coord{0, 0, 0}, 8, 4.0, 4.0);
  ASSERT_TRUE(cone.has_value());
  const Coord origin{16, -8, 24};
  const std::vector<GridTriangle> reversed = reversed_cone_triangles(*cone, origin);
  ASSERT_EQ(reversed.size(), cone->segments.size());
  // The hemisphere plus the reversed cone (shifted by the origin) is closed: every directed
  // edge's reverse is used too.
  std::map<std::pair<std::array<double, 3>, std::array<double, 3>>, int> uses;
  auto key = [](const Vec3d& v) { return std::array<double, 3>{v.x, v.y, v.z}; };
  const Vec3d o{16, -8, 24};
  for (const auto& f : m.triangles)
    for (int k = 0; k < 3; ++k)
      ++uses[{key(m.vertices[f[k]] + o), key(m.vertices[f[(k + 1) % 3]] + o)}];
  for (const GridTriangle& t : reversed)
    for (int k = 0; k < 3; ++k) ++uses[{key(t.corner[k]), key(t.corner[(k + 1) % 3])}];
  int unmatched = 0;
  for (const auto& [edge, count] : uses) {
    const auto back = uses.find({edge.second, edge.first});
    unmatched += back == uses.end() || back->second != count;
  }
  EXPECT_EQ(unmatched, 0);
}

}  // namespace
}  // namespace levelset
