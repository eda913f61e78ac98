// redistanced_near (reconstruction_parts.hpp): after a pass that moved the front in a few
// bricks, redistancing only near them gives the whole band's redistance, and leaves the rest.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "apps/reconstruction_parts.hpp"
#include "distance/redistance.hpp"
#include "grid/band_accessor.hpp"
#include "grid/build_from_sdf.hpp"

namespace levelset::apps::detail {
namespace {

TEST(RedistancedNear, MatchesTheWholeBandsRedistanceAndKeepsTheRest) {
  constexpr double kRadius = 0.5, kW = 3.0;
  BBox box;
  box.extend({-kRadius, -kRadius, -kRadius});
  box.extend({kRadius, kRadius, kRadius});
  SdfBuildOptions options;
  options.frame = frame_for_resolution(box, 96, kW);
  RedistanceOptions redo;
  redo.half_width = kW;
  // As in the reconstruction, the band before the pass is a redistanced one.
  const NarrowBand sphere =
      redistance(
          build_from_sdf([](const Vec3d& p) { return length(p) - kRadius; }, box, options).band,
          redo)
          .band;
  const double h = sphere.voxel_size();
  // A pass moved the front outward by 0.6 voxel in the bricks of the cap x > 0.3 only.
  std::vector<std::uint64_t> moved;
  NarrowBand passed = sphere;
  std::vector<float> values(sphere.values().begin(), sphere.values().end());
  std::size_t i = 0;
  sphere.for_each_active([&](const Coord& c, float) {
    if (brick_origin(brick_of(c)).x * h + sphere.origin().x > 0.3) {
      values[i] -= float(0.6 * h);
      moved.push_back(brick_key(brick_of(c)));
    }
    ++i;
  });
  passed.swap_values(values);
  std::sort(moved.begin(), moved.end());
  moved.erase(std::unique(moved.begin(), moved.end()), moved.end());
  ASSERT_GT(moved.size(), 4u);
  ASSERT_LT(moved.size(), sphere.brick_count() / 4);

  const NarrowBand whole = redistance(reframed(passed, {}, kW - 1.0), redo).band;
  const NarrowBand near = redistanced_near(passed, moved, kW, 1.0, {});
  // Both hold the same voxels but at the band's very edge (|u| within 0.01 voxel of W h, which a
  // redistance of a redistanced band admits or drops anew), with the same signs and values.
  const float edge = float((kW - 0.01) * h);
  BandAccessor at_near(near), at_whole(whole), at_passed(passed);
  double worst = 0.0;
  std::size_t compared = 0;
  whole.for_each_active([&](const Coord& c, float v) {
    if (std::abs(v) >= edge) return;
    const std::optional<float> u = at_near.probe(c);
    ASSERT_TRUE(u.has_value());
    EXPECT_EQ(*u < 0.0f, v < 0.0f);
    worst = std::max(worst, std::abs(double(*u) - double(v)) / h);
    ++compared;
  });
  near.for_each_active([&](const Coord& c, float u) {
    if (std::abs(u) < edge) {
      EXPECT_TRUE(at_whole.probe(c).has_value());
    }
  });
  EXPECT_GT(compared, 10000u);
  EXPECT_LT(worst, 2e-4);  // the sweeps stop at a tolerance; 7e-5 measured
  // Far from the moved bricks the values are the pass's own, untouched.
  std::size_t kept = 0;
  near.for_each_active_world([&](const Coord& c, const Vec3d& p, float v) {
    if (p.x > -0.2) return;
    const std::optional<float> u = at_passed.probe(c);
    ASSERT_TRUE(u.has_value());
    EXPECT_EQ(*u, v);
    ++kept;
  });
  EXPECT_GT(kept, 1000u);
}

}  // namespace
}  // namespace levelset::apps::detail
