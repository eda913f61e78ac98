// sign_components: components of the inside and outside voxel sets of a band, checked on
// shapes whose components are known: two disjoint balls, a hollow ball (a cavity), and two
// balls that touch only along a voxel edge.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "core/error.hpp"
#include "grid/build_from_sdf.hpp"
#include "grid/sign_components.hpp"

namespace levelset {
namespace {

NarrowBand band_of(const std::function<double(const Vec3d&)>& sdf, const BBox& bounds, double h) {
  SdfBuildOptions o;
  o.frame = GridFrame{h, Vec3d{0, 0, 0}, 3.0};
  return build_from_sdf(sdf, bounds, o).band;
}

BBox box(double lo, double hi) {
  BBox b;
  b.min = {lo, lo, lo};
  b.max = {hi, hi, hi};
  return b;
}

std::size_t count(const SignComponentsResult& r, bool inside) {
  return std::size_t(std::count_if(r.components.begin(), r.components.end(),
                                   [&](const SignComponent& c) { return c.inside == inside; }));
}

TEST(SignComponents, TwoBallsAreTwoInsideComponentsAndOneExterior) {
  const Vec3d a{-1.0, 0, 0}, b{1.0, 0, 0};
  const NarrowBand band = band_of(
      [&](const Vec3d& p) { return std::min(length(p - a), length(p - b)) - 0.6; }, box(-2, 2), 0.1);
  const SignComponentsResult r = sign_components(band);
  ASSERT_EQ(count(r, true), 2u);
  ASSERT_EQ(count(r, false), 1u);
  for (const SignComponent& c : r.components) {
    EXPECT_EQ(c.touches_box, !c.inside);
    EXPECT_FALSE(c.front.empty());
    if (!c.inside) continue;
    // A ball of radius 6 voxels: about (4/3) pi 6^3 = 905 voxels, all within the band's 3
    // voxels of the front except the ball's core.
    EXPECT_NEAR(double(c.voxels), 4.0 / 3.0 * M_PI * 216.0, 60.0);
    EXPECT_FALSE(c.all_active);
  }
  // Labels agree with the signs everywhere.
  const Coord centre_a{-10, 0, 0}, gap{0, 0, 0};
  EXPECT_TRUE(r.components[std::size_t(r.label[r.index_of(centre_a)])].inside);
  EXPECT_FALSE(r.components[std::size_t(r.label[r.index_of(gap)])].inside);
}

TEST(SignComponents, HollowBallHasACavityThatDoesNotTouchTheBox) {
  const NarrowBand band = band_of([](const Vec3d& p) { return std::abs(length(p) - 1.0) - 0.3; }, box(-2, 2), 0.1);
  const SignComponentsResult r = sign_components(band);
  ASSERT_EQ(count(r, true), 1u);
  ASSERT_EQ(count(r, false), 2u);
  int cavities = 0;
  for (const SignComponent& c : r.components)
    if (!c.inside && !c.touches_box) {
      ++cavities;
      EXPECT_NEAR(double(c.voxels), 4.0 / 3.0 * M_PI * 343.0, 80.0);  // radius 0.7 = 7 voxels
    }
  EXPECT_EQ(cavities, 1);
}

TEST(SignComponents, EdgeContactJoinsUnder26AndSeparatesUnder6) {
  // Two unit cubes of voxels sharing only the edge x = y = 0: inside voxels (-1,-1,z) and (0,0,z).
  const NarrowBand band = band_of(
      [](const Vec3d& p) {
        auto cube = [&](double cx, double cy) {
          const Vec3d q{std::abs(p.x - cx), std::abs(p.y - cy), std::abs(p.z)};
          return std::max({q.x, q.y, q.z}) - 0.25;
        };
        return std::min(cube(-0.5, -0.5), cube(0.0, 0.0));
      },
      box(-2, 2), 1.0 / 2.0);
  SignComponentsOptions o;
  EXPECT_EQ(count(sign_components(band, o), true), 1u);
  o.inside_connectivity = 6;
  EXPECT_EQ(count(sign_components(band, o), true), 2u);
}

TEST(SignComponents, BadOptionsAndHugeBoxesGiveTypedErrors) {
  const NarrowBand band = band_of([](const Vec3d& p) { return length(p) - 1.0; }, box(-2, 2), 0.1);
  SignComponentsOptions o;
  o.inside_connectivity = 18;
  try {
    sign_components(band, o);
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::InvalidArgument);
  }
  o.inside_connectivity = 26;
  o.max_voxels = 1000;
  try {
    sign_components(band, o);
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::LimitExceeded);
  }
  EXPECT_TRUE(sign_components(NarrowBand{}).components.empty());
}

}  // namespace
}  // namespace levelset
