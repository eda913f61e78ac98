#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

#include "core/error.hpp"
#include "geometry/analytic_shapes.hpp"

namespace levelset {
namespace {

constexpr double kPi = std::numbers::pi;

TEST(AnalyticShapes, ClosedFormValues) {
  const auto sphere = make_sphere({1, 2, 3}, 2.0);
  EXPECT_DOUBLE_EQ(sphere->distance({1, 2, 3}), -2.0);
  EXPECT_DOUBLE_EQ(sphere->distance({1, 2, 8}), 3.0);

  const auto box = make_box({0, 0, 0}, {1, 2, 3});
  EXPECT_DOUBLE_EQ(box->distance({0, 0, 0}), -1.0);
  EXPECT_DOUBLE_EQ(box->distance({2, 0, 0}), 1.0);
  EXPECT_DOUBLE_EQ(box->distance({4, 6, 3}), 5.0);  // corner (1,2,3) -> (4,6,3): 3-4-0
  EXPECT_NEAR(box->distance({0.5, 1.9, 0}), -0.1, 1e-15);

  const auto torus = make_torus({0, 0, 0}, 2.0, 0.5);
  EXPECT_DOUBLE_EQ(torus->distance({2, 0, 0}), -0.5);
  EXPECT_DOUBLE_EQ(torus->distance({0, 0, 0}), 1.5);
  EXPECT_DOUBLE_EQ(torus->distance({0, 3, 0}), 0.5);

  const auto db = make_dumbbell({0, 0, 0}, 0.5, 1.0, 0.2);
  EXPECT_NEAR(db->distance({1, 0, 0}), -0.5, 1e-15);   // sphere center
  EXPECT_NEAR(db->distance({1.5, 0, 0}), 0.0, 1e-15);  // sphere tip
  EXPECT_NEAR(db->distance({0, 0, 0}), -0.2, 1e-15);   // bar center
  EXPECT_NEAR(db->distance({0, 0.2, 0}), 0.0, 1e-15);  // bar surface
  EXPECT_NEAR(db->distance({0, 0, 0.7}), 0.5, 1e-15);  // above the bar
}

TEST(AnalyticShapes, RejectsBadParametersAndUnknownNames) {
  EXPECT_THROW(make_sphere({0, 0, 0}, -1), Error);
  EXPECT_THROW(make_torus({0, 0, 0}, 1, 2), Error);
  EXPECT_THROW(make_dumbbell({0, 0, 0}, 0.5, 0.3, 0.2), Error);  // spheres overlap
  EXPECT_THROW(make_torus_knot({0, 0, 0}, 2, 4, 1, 0.4, 0.1), Error);  // not coprime
  try {
    make_builtin_shape("teapot");
    FAIL();
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::InvalidArgument);
    EXPECT_NE(std::string(e.reason()).find("knot"), std::string::npos);
  }
}

// Every builtin SDF is 1-Lipschitz and its gradient has unit length away from kinks,
// which is what "signed distance" means and what build_from_sdf's pruning relies on.
class ShapeSdf : public ::testing::TestWithParam<std::string> {};

TEST_P(ShapeSdf, IsLipschitzWithUnitGradient) {
  const auto s = make_builtin_shape(GetParam());
  const BBox b = s->bounds();
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(-0.3, 1.3);
  int unit_gradients = 0;
  for (int i = 0; i < 4000; ++i) {
    const Vec3d p{b.min.x + u(rng) * (b.max.x - b.min.x), b.min.y + u(rng) * (b.max.y - b.min.y),
                  b.min.z + u(rng) * (b.max.z - b.min.z)};
    const Vec3d q = p + Vec3d{u(rng) - 0.5, u(rng) - 0.5, u(rng) - 0.5} * 0.2;
    ASSERT_LE(std::abs(s->distance(p) - s->distance(q)), length(p - q) * (1 + 1e-9) + 1e-12);
    const double e = 1e-6;
    const Vec3d g{(s->distance(p + Vec3d{e, 0, 0}) - s->distance(p - Vec3d{e, 0, 0})) / (2 * e),
                  (s->distance(p + Vec3d{0, e, 0}) - s->distance(p - Vec3d{0, e, 0})) / (2 * e),
                  (s->distance(p + Vec3d{0, 0, e}) - s->distance(p - Vec3d{0, 0, e})) / (2 * e)};
    if (std::abs(length(g) - 1.0) < 1e-4) ++unit_gradients;
  }
  EXPECT_GT(unit_gradients, 3800);  // all but points near the medial axis / box edges
}

INSTANTIATE_TEST_SUITE_P(Builtins, ShapeSdf,
                         ::testing::Values("sphere", "box", "torus", "dumbbell", "knot"));

Vec3d knot_curve(double t) {
  const double s = 1.0 + 0.4 * std::cos(3 * t);
  return {s * std::cos(2 * t), s * std::sin(2 * t), 0.4 * std::sin(3 * t)};
}

// Brute force: dense sampling of the curve, then golden-section refinement around the best.
double knot_distance_reference(const Vec3d& p) {
  const int n = 200000;
  double best = 1e300, bt = 0;
  for (int i = 0; i < n; ++i) {
    const double t = 2 * kPi * i / n;
    const double d = length(knot_curve(t) - p);
    if (d < best) { best = d; bt = t; }
  }
  double lo = bt - 2 * kPi / n, hi = bt + 2 * kPi / n;
  const double g = (std::sqrt(5.0) - 1) / 2;
  for (int it = 0; it < 80; ++it) {
    const double a = hi - g * (hi - lo), b = lo + g * (hi - lo);
    if (length(knot_curve(a) - p) < length(knot_curve(b) - p)) hi = b; else lo = a;
  }
  return std::min(best, length(knot_curve(0.5 * (lo + hi)) - p)) - 0.15;
}

TEST(AnalyticShapes, KnotDistanceMatchesBruteForce) {
  const auto knot = make_builtin_shape("knot");
  std::mt19937_64 rng(9);
  std::uniform_real_distribution<double> u(-1.6, 1.6);
  for (int i = 0; i < 60; ++i) {
    const Vec3d p{u(rng), u(rng), u(rng) * 0.5};
    EXPECT_NEAR(knot->distance(p), knot_distance_reference(p), 1e-9) << p.x << " " << p.y << " " << p.z;
  }
}

TEST(AnalyticShapes, KnotTubeDoesNotTouchItself) {
  // Points of the curve further apart than pi/2 in parameter must be more than two tube
  // radii apart, otherwise the tube self-intersects and the surface is not a genus-1 knot.
  const int n = 1500;
  double closest = 1e300;
  for (int i = 0; i < n; ++i)
    for (int j = i + 1; j < n; ++j) {
      const double ti = 2 * kPi * i / n, tj = 2 * kPi * j / n;
      const double sep = std::min(tj - ti, 2 * kPi - (tj - ti));
      if (sep > kPi / 2) closest = std::min(closest, length(knot_curve(ti) - knot_curve(tj)));
    }
  EXPECT_GT(closest, 2 * 0.15 * 1.2);
}

TEST(AnalyticShapes, DumbbellMatchesSampledProfile) {
  const double rs = 0.5, d = 0.75, rb = 0.15;
  const auto db = make_dumbbell({0, 0, 0}, rs, d, rb);
  // Profile boundary samples in the meridian half-plane.
  std::vector<std::pair<double, double>> prof;
  const double xj = d - std::sqrt(rs * rs - rb * rb);
  const double tj = kPi - std::asin(rb / rs);
  for (int i = 0; i <= 200000; ++i) {
    const double t = tj * i / 200000.0;
    prof.push_back({d + rs * std::cos(t), rs * std::sin(t)});
    prof.push_back({-d - rs * std::cos(t), rs * std::sin(t)});
    prof.push_back({-xj + 2 * xj * i / 200000.0, rb});
  }
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-1.5, 1.5);
  for (int i = 0; i < 40; ++i) {
    const Vec3d p{u(rng), u(rng) * 0.5, u(rng) * 0.5};
    const double x = p.x, rho = std::hypot(p.y, p.z);
    double best = 1e300;
    for (auto [px, pr] : prof) best = std::min(best, std::hypot(x - px, rho - pr));
    EXPECT_NEAR(std::abs(db->distance(p)), best, 2e-5);
  }
}

}  // namespace
}  // namespace levelset
