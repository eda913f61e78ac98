#include <gtest/gtest.h>

#include <boost/multiprecision/cpp_int.hpp>
#include <cmath>
#include <random>

#include "distance/exact_predicates.hpp"
#include "distance/solid_angle.hpp"

namespace levelset {
namespace {

using Rational = boost::multiprecision::cpp_rational;

int reference_orient2d(double ax, double ay, double bx, double by, double cx, double cy) {
  const Rational d = (Rational(ax) - Rational(cx)) * (Rational(by) - Rational(cy)) -
                     (Rational(ay) - Rational(cy)) * (Rational(bx) - Rational(cx));
  return d > 0 ? 1 : (d < 0 ? -1 : 0);
}

int reference_orient3d(const Vec3d& a, const Vec3d& b, const Vec3d& c, const Vec3d& d) {
  auto R = [](double v) { return Rational(v); };
  const Rational adx = R(a.x) - R(d.x), ady = R(a.y) - R(d.y), adz = R(a.z) - R(d.z);
  const Rational bdx = R(b.x) - R(d.x), bdy = R(b.y) - R(d.y), bdz = R(b.z) - R(d.z);
  const Rational cdx = R(c.x) - R(d.x), cdy = R(c.y) - R(d.y), cdz = R(c.z) - R(d.z);
  const Rational det =
      adz * (bdx * cdy - cdx * bdy) + bdz * (cdx * ady - adx * cdy) + cdz * (adx * bdy - bdx * ady);
  return det > 0 ? 1 : (det < 0 ? -1 : 0);
}

TEST(ExactPredicates, Orient2dMatchesRationalsOnNearlyCollinearPoints) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> U(-1000.0, 1000.0);
  std::uniform_real_distribution<double> T(-2.0, 3.0);
  int zeros = 0, naive_wrong = 0;
  for (int i = 0; i < 20000; ++i) {
    const double ax = U(rng), ay = U(rng), bx = U(rng), by = U(rng);
    // c on the line through a and b, rounded: the true sign is decided in the last bits.
    const double t = T(rng);
    double cx = ax + t * (bx - ax), cy = ay + t * (by - ay);
    if (i % 4 == 0) {
      cx = ax;
      cy = ay;
    }  // exact degeneracy
    if (i % 7 == 0) cx = std::nextafter(cx, 1e9);
    const int ref = reference_orient2d(ax, ay, bx, by, cx, cy);
    ASSERT_EQ(orient2d_sign(ax, ay, bx, by, cx, cy), ref) << i;
    ASSERT_EQ(orient2d_exact(ax, ay, bx, by, cx, cy), ref) << i;
    const double naive = (ax - cx) * (by - cy) - (ay - cy) * (bx - cx);
    naive_wrong += (naive > 0 ? 1 : (naive < 0 ? -1 : 0)) != ref;
    zeros += ref == 0;
  }
  EXPECT_GT(zeros, 1000);
  EXPECT_GT(naive_wrong, 100);  // the test does exercise the exact path
}

TEST(ExactPredicates, Orient3dMatchesRationalsOnNearlyCoplanarPoints) {
  std::mt19937_64 rng(12);
  std::uniform_real_distribution<double> U(-100.0, 100.0);
  std::uniform_real_distribution<double> T(-1.0, 2.0);
  int zeros = 0, naive_wrong = 0;
  for (int i = 0; i < 5000; ++i) {
    const Vec3d a{U(rng), U(rng), U(rng)}, b{U(rng), U(rng), U(rng)}, c{U(rng), U(rng), U(rng)};
    const double s = T(rng), t = T(rng);
    Vec3d d = a + (b - a) * s + (c - a) * t;
    if (i % 5 == 0) d = Vec3d{std::round(a.x), std::round(a.y), std::round(a.z)};
    if (i % 5 == 1) d = b;
    if (i % 9 == 0) d.z = std::nextafter(d.z, -1e9);
    const int ref = reference_orient3d(a, b, c, d);
    ASSERT_EQ(orient3d_sign(a, b, c, d), ref) << i;
    ASSERT_EQ(orient3d_exact(a, b, c, d), ref) << i;
    const double adx = a.x - d.x, ady = a.y - d.y, adz = a.z - d.z, bdx = b.x - d.x,
                 bdy = b.y - d.y, bdz = b.z - d.z, cdx = c.x - d.x, cdy = c.y - d.y,
                 cdz = c.z - d.z;
    const double naive = adz * (bdx * cdy - cdx * bdy) + bdz * (cdx * ady - adx * cdy) +
                         cdz * (adx * bdy - bdx * ady);
    naive_wrong += (naive > 0 ? 1 : (naive < 0 ? -1 : 0)) != ref;
    zeros += ref == 0;
  }
  EXPECT_GT(zeros, 500);
  EXPECT_GT(naive_wrong, 50);
}

// Marching-cubes meshes re-sampled at their own resolution: vertices lie on grid lines (two
// integer coordinates, the third a fraction), probed from integer voxel centres. Most tests
// are exact ties or decided in the last bits: the stack expansions must match rationals.
TEST(ExactPredicates, GridAlignedInputsMatchRationals) {
  std::mt19937_64 rng(13);
  std::uniform_int_distribution<int> I(0, 6);
  std::uniform_real_distribution<double> F(0.0, 1.0);
  auto on_grid_line = [&] {
    Vec3d v{double(I(rng)), double(I(rng)), double(I(rng))};
    v[int(rng() % 3)] += (rng() % 3 == 0) ? 0.5 : F(rng);  // exact midpoints, and arbitrary
    return v;
  };
  int zeros2 = 0, zeros3 = 0;
  for (int i = 0; i < 20000; ++i) {
    const Vec3d a = on_grid_line(), b = on_grid_line(), c = on_grid_line();
    const Vec3d p{double(I(rng)), double(I(rng)), double(I(rng))};
    const int ref2 = reference_orient2d(a.x, a.y, b.x, b.y, p.x, p.y);
    ASSERT_EQ(orient2d_exact(a.x, a.y, b.x, b.y, p.x, p.y), ref2) << i;
    ASSERT_EQ(orient2d_sign(a.x, a.y, b.x, b.y, p.x, p.y), ref2) << i;
    const int ref3 = reference_orient3d(a, b, c, p);
    ASSERT_EQ(orient3d_exact(a, b, c, p), ref3) << i;
    ASSERT_EQ(orient3d_sign(a, b, c, p), ref3) << i;
    zeros2 += ref2 == 0;
    zeros3 += ref3 == 0;
  }
  EXPECT_GT(zeros2, 500);
  EXPECT_GT(zeros3, 40);
}

// Many-component expansions: coordinates spread over 2^-60 .. 2^60 make every difference
// and product inexact, so sums of several hundred bits decide the sign.
TEST(ExactPredicates, WideDynamicRangeMatchesRationals) {
  std::mt19937_64 rng(14);
  std::uniform_int_distribution<int> E(-60, 60);
  std::uniform_real_distribution<double> M(-1.0, 1.0);
  auto wide = [&] { return std::ldexp(M(rng), E(rng)); };
  for (int i = 0; i < 3000; ++i) {
    const Vec3d a{wide(), wide(), wide()}, b{wide(), wide(), wide()}, c{wide(), wide(), wide()};
    Vec3d d = a + (b - a) * M(rng) + (c - a) * M(rng);  // near the plane, rounded
    if (i % 3 == 0) d.x = std::nextafter(d.x, 1e300);
    ASSERT_EQ(orient3d_exact(a, b, c, d), reference_orient3d(a, b, c, d)) << i;
    ASSERT_EQ(orient2d_exact(a.x, a.y, b.x, b.y, d.x, d.y), reference_orient2d(a.x, a.y, b.x, b.y, d.x, d.y))
        << i;
  }
}

TEST(ExactPredicates, Orient3dSignConvention) {
  // Counterclockwise triangle seen from +z; a point below it (behind) is positive.
  const Vec3d a{0, 0, 0}, b{1, 0, 0}, c{0, 1, 0};
  EXPECT_EQ(orient3d_sign(a, b, c, {0.2, 0.2, -1}), 1);
  EXPECT_EQ(orient3d_sign(a, b, c, {0.2, 0.2, 1}), -1);
  EXPECT_EQ(orient3d_sign(a, b, c, {5, 7, 0}), 0);
  EXPECT_EQ(orient2d_sign(0, 0, 1, 0, 0, 1), 1);
}

TEST(SolidAngle, SignAndOctantAndPlane) {
  // The triangle (e_x, e_y, e_z) covers one octant (4 pi / 8) seen from the origin, which lies
  // behind it (its normal points away from the origin).
  const Vec3d ex{1, 0, 0}, ey{0, 1, 0}, ez{0, 0, 1};
  EXPECT_NEAR(triangle_solid_angle({0, 0, 0}, ex, ey, ez), std::numbers::pi / 2, 1e-14);
  EXPECT_NEAR(triangle_solid_angle({0, 0, 0}, ex, ez, ey), -std::numbers::pi / 2, 1e-14);
  // In the plane: exactly zero, inside the triangle or not, and for degenerate triangles.
  EXPECT_EQ(triangle_solid_angle({0.25, 0.25, 0.5}, ex, ey, ez), 0.0);
  EXPECT_EQ(triangle_solid_angle({0.2, 0.3, 0.0}, {0, 0, 0}, ex, ey), 0.0);
  EXPECT_EQ(triangle_solid_angle({0.2, 0.3, 0.7}, {0, 0, 0}, ex, ex * 2.0), 0.0);
  // Just behind / in front of the centre: +-2 pi in the limit.
  EXPECT_NEAR(triangle_solid_angle({0.25, 0.25, -1e-9}, {0, 0, 0}, ex, ey), 2 * std::numbers::pi,
              1e-6);
  EXPECT_NEAR(triangle_solid_angle({0.25, 0.25, 1e-9}, {0, 0, 0}, ex, ey), -2 * std::numbers::pi,
              1e-6);
}

TEST(SolidAngle, PolynomialArctangentFollowsTheLibraryOne) {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> angle(-std::numbers::pi, std::numbers::pi);
  std::uniform_real_distribution<double> scale(-30.0, 30.0);
  double worst = 0.0;
  for (int i = 0; i < 200000; ++i) {
    const double a = angle(rng), r = std::exp2(scale(rng));
    const double y = r * std::sin(a), x = r * std::cos(a);
    worst = std::max(worst, std::abs(polynomial_atan2(y, x) - std::atan2(y, x)));
  }
  EXPECT_LT(worst, 2e-8);
  // Axes and the branch cut: atan2's values, and 0 on the x axis (either side).
  EXPECT_NEAR(polynomial_atan2(1.0, 0.0), std::numbers::pi / 2, 2e-8);
  EXPECT_NEAR(polynomial_atan2(-1.0, 0.0), -std::numbers::pi / 2, 2e-8);
  EXPECT_NEAR(polynomial_atan2(1e-300, -1.0), std::numbers::pi, 2e-8);
  EXPECT_NEAR(polynomial_atan2(-1e-300, -1.0), -std::numbers::pi, 2e-8);
  EXPECT_EQ(polynomial_atan2(0.0, -1.0), 0.0);
  EXPECT_EQ(polynomial_atan2(0.0, 0.0), 0.0);
  // The fast solid angle against the exact one, from random points.
  std::uniform_real_distribution<double> U(-2.0, 2.0);
  const Vec3d a{0.1, -0.2, 0.3}, b{1.1, 0.4, -0.2}, c{-0.3, 0.9, 0.5};
  double worst_angle = 0.0;
  for (int i = 0; i < 20000; ++i) {
    const Vec3d q{U(rng), U(rng), U(rng)};
    worst_angle = std::max(worst_angle, std::abs(fast_triangle_solid_angle(q, a, b, c) -
                                                 triangle_solid_angle(q, a, b, c)));
  }
  EXPECT_LT(worst_angle, 4e-8);
}

}  // namespace
}  // namespace levelset
