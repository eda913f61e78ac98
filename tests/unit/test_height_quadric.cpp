// The height fit's quadric (apps/height_quadric.hpp): its weight polynomial against std::exp,
// an exact quadric recovered from its own points (coefficients, residual 0, the offset along
// the tilted normal), the spread against its definition, and the degenerate inputs it refuses.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <random>
#include <vector>

#include "apps/height_quadric.hpp"

namespace levelset::apps::detail {
namespace {

TEST(HeightQuadric, WeightPolynomialIsExpToRounding) {
  double worst = 0.0;
  for (int i = 0; i <= 100000; ++i) {
    const double s = 1.000001 * double(i) / 100000.0;
    worst = std::max(worst, std::abs(exp_minus_unit(s) / std::exp(-s) - 1.0));
  }
  EXPECT_LT(worst, 1e-15);
}

std::vector<TangentPoint> on_quadric(const std::array<double, 6>& c, double radius, int n,
                                     double noise, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-radius, radius);
  std::normal_distribution<double> g(0.0, noise);
  std::vector<TangentPoint> p;
  while (int(p.size()) < n) {
    const double xi = u(rng), eta = u(rng);
    if (xi * xi + eta * eta > radius * radius) continue;
    // The coefficients are over (xi, eta) / radius' scale; the fit's own R is the farthest point.
    const double z =
        c[0] + c[1] * xi + c[2] * eta + c[3] * xi * xi + c[4] * xi * eta + c[5] * eta * eta;
    p.push_back({xi, eta, z + (noise > 0.0 ? g(rng) : 0.0)});
  }
  return p;
}

TEST(HeightQuadric, RecoversAnExactQuadric) {
  const std::array<double, 6> c{0.3, 0.2, -0.1, 0.5, -0.25, 0.15};  // in world units of (xi, eta)
  for (const int n : {10, 33, 131, 256}) {                          // lane remainders 2, 1, 3, 0
    const auto p = on_quadric(c, 1.5, n, 0.0, unsigned(n));
    for (const bool spread : {false, true}) {
      const HeightFit f = quadric_height(p.data(), n, spread);
      ASSERT_TRUE(f.ok) << n;
      const double R = 1.0 / f.inv_r;
      const double want[6] = {c[0], c[1] * R, c[2] * R, c[3] * R * R, c[4] * R * R, c[5] * R * R};
      for (std::size_t i = 0; i < 6; ++i) EXPECT_NEAR(f.c[i], want[i], 1e-10) << n << " c" << i;
      EXPECT_LT(f.residual, 1e-10);
      EXPECT_NEAR(f.offset, -c[0] / std::sqrt(1.0 + c[1] * c[1] + c[2] * c[2]), 1e-10);
      EXPECT_EQ(f.spread > 0.0, spread);
    }
  }
}

TEST(HeightQuadric, SpreadIsTheOffsetsStandardErrorPerUnitNoise) {
  // Var(c0) / sigma^2 over many noisy draws of the same positions against the fit's spread^2.
  const std::array<double, 6> c{0.0, 0.1, 0.0, 0.2, 0.0, 0.1};
  const auto base = on_quadric(c, 1.0, 128, 0.0, 5);
  const double sigma = 0.01;
  std::mt19937_64 rng(6);
  std::normal_distribution<double> g(0.0, sigma);
  double sum = 0.0, sum2 = 0.0, spread = 0.0;
  const int draws = 4000;
  for (int t = 0; t < draws; ++t) {
    auto p = base;
    for (auto& q : p) q.z += g(rng);
    const HeightFit f = quadric_height(p.data(), int(p.size()), true);
    ASSERT_TRUE(f.ok);
    sum += f.c[0];
    sum2 += f.c[0] * f.c[0];
    spread = f.spread;  // depends on the positions only
  }
  const double var = sum2 / draws - (sum / draws) * (sum / draws);
  EXPECT_NEAR(std::sqrt(var) / sigma, spread, 0.05 * spread);  // 4000 draws: ~1.1 % standard error
}

TEST(HeightQuadric, RefusesDegeneratePoints) {
  std::vector<TangentPoint> line, axis;
  for (int i = 0; i < 40; ++i) {
    line.push_back({0.1 * i, 0.05 * i, 0.01 * i});  // one tangential line: u, v, uv... dependent
    axis.push_back({0.0, 0.0, 0.1 * i});            // all on the normal line: no radius
  }
  EXPECT_FALSE(quadric_height(line.data(), 40, true).ok);
  EXPECT_FALSE(quadric_height(axis.data(), 40, true).ok);
  EXPECT_FALSE(quadric_height(line.data(), 9, false).ok);  // fewer than 10
}

}  // namespace
}  // namespace levelset::apps::detail
