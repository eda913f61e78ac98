// The fan apex marching cubes and surface nets choose for a contour polygon: the one whose fan
// has the largest smallest angle, checked against that criterion evaluated in double with
// angles (acos) on convex polygons of 4 to 12 vertices, nearly planar as cell loops are.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include "surface/surface_common.hpp"

namespace levelset {
namespace {

double smallest_angle(const Vec3d& a, const Vec3d& b, const Vec3d& c) {
  auto angle = [](const Vec3d& at, const Vec3d& p, const Vec3d& q) {
    const Vec3d u = p - at, v = q - at;
    return std::acos(std::clamp(dot(u, v) / (length(u) * length(v)), -1.0, 1.0));
  };
  return std::min({angle(a, b, c), angle(b, c, a), angle(c, a, b)});
}

// The smallest angle over the fan of polygon p from apex s.
double fan_quality(const std::vector<Vec3d>& p, int s) {
  const int n = int(p.size());
  double worst = std::numbers::pi;
  for (int i = 1; i + 1 < n; ++i) worst = std::min(worst, smallest_angle(p[s], p[(s + i) % n], p[(s + i + 1) % n]));
  return worst;
}

TEST(FanChoice, PicksTheFanWithTheLargestSmallestAngle) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  int apexes_other_than_first = 0;
  for (int n = 4; n <= 12; ++n)
    for (int trial = 0; trial < 400; ++trial) {
      // Sorted random angles on an ellipse, lifted slightly out of its plane: convex, irregular.
      // Quads stay planar: their split is the Delaunay diagonal, which maximises the smallest
      // angle in the plane (out of it, two close vertices can tilt the comparison).
      std::vector<double> angles(static_cast<std::size_t>(n));
      for (double& t : angles) t = 2.0 * std::numbers::pi * unit(rng);
      std::sort(angles.begin(), angles.end());
      const double rx = 0.5 + unit(rng), ry = 0.5 + unit(rng);
      std::vector<Vec3d> p;
      for (double t : angles) p.push_back({rx * std::cos(t), ry * std::sin(t), n == 4 ? 0.0 : 0.02 * (unit(rng) - 0.5)});
      const int chosen = surface_detail::best_fan_start(p.data(), n);
      ASSERT_GE(chosen, 0);
      ASSERT_LT(chosen, n);
      double best = 0.0;
      for (int s = 0; s < n; ++s) best = std::max(best, fan_quality(p, s));
      // The choice is made in float from squared lengths: equal to the best within its rounding.
      EXPECT_NEAR(fan_quality(p, chosen), best, n == 4 ? 1e-9 : 1e-3) << "n " << n << " trial " << trial;
      apexes_other_than_first += chosen != 0;
    }
  EXPECT_GT(apexes_other_than_first, 1000);  // the choice matters: not always the first apex
}

TEST(FanChoice, DegeneratePolygonsGiveAnApexInRange) {
  // Repeated vertices (zero-length sides) and collinear ones: no NaN reaches the choice.
  for (int n = 4; n <= 12; ++n) {
    std::vector<Vec3d> same(std::size_t(n), Vec3d{1.0, 2.0, 3.0});
    std::vector<Vec3d> line;
    for (int i = 0; i < n; ++i) line.push_back({double(i), 0.0, 0.0});
    for (const auto* p : {&same, &line}) {
      const int chosen = surface_detail::best_fan_start(p->data(), n);
      EXPECT_GE(chosen, 0);
      EXPECT_LT(chosen, n);
    }
  }
}

}  // namespace
}  // namespace levelset
