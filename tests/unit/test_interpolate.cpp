#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "core/error.hpp"
#include "grid/interpolate.hpp"
#include "shape_band.hpp"

namespace levelset {
namespace {

TEST(SampleTrilinear, ExactAtVoxelsAndCloseToTheSdfInTheBand) {
  const auto sb = test::make_shape_band("sphere", 64);
  const NarrowBand& band = sb.band;
  BandAccessor acc(band);
  const double h = band.voxel_size();
  band.for_each_active_world([&](const Coord& c, const Vec3d& p, float v) {
    ASSERT_EQ(sample_trilinear(acc, band, p), v) << c.x;
  });
  std::mt19937_64 rng(1);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  int inside_band = 0;
  for (int i = 0; i < 20000; ++i) {
    const Vec3d p{u(rng) * 1.1, u(rng) * 1.1, u(rng) * 1.1};
    const double d = sb.shape->distance(p);
    const float s = sample_trilinear(acc, band, p);
    ASSERT_TRUE(std::isfinite(s));
    if (std::abs(d) < band.background() - 2 * h) {
      ++inside_band;
      ASSERT_NEAR(s, d, h * h * 2.0);  // trilinear error of a smooth distance ~ h^2 / R
    } else if (std::abs(d) > band.background() + 2 * h) {
      ASSERT_EQ(s, d < 0 ? -band.background() : band.background());  // band limit, right sign
    }
  }
  EXPECT_GT(inside_band, 500);
}

TEST(SampleTrilinear, FarAwayAndInvalidPoints) {
  const auto sb = test::make_shape_band("torus", 96);  // band much thinner than the tube
  BandAccessor acc(sb.band);
  EXPECT_EQ(sample_trilinear(acc, sb.band, {1e30, 0, 0}), sb.band.background());
  EXPECT_EQ(sample_trilinear(acc, sb.band, {0, 50, -3}), sb.band.background());
  EXPECT_EQ(sample_trilinear(acc, sb.band, {1.0, 0, 0}), -sb.band.background());  // tube core
  EXPECT_THROW(sample_trilinear(acc, sb.band, {std::nan(""), 0, 0}), Error);
}

}  // namespace
}  // namespace levelset
