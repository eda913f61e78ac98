// The carving's Euler count (reconstruction_parts.hpp euler_lost), which decides where a web
// of the start shell may be cut: against the known topology of solids with a voxel region
// removed (a torus cut through, a ball drilled through, a dent, a hollow).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <vector>

#include "apps/reconstruction_parts.hpp"
#include "grid/band_accessor.hpp"
#include "shape_band.hpp"

namespace levelset::apps::detail {
namespace {

// The inside voxels of `band` (within `reach` voxels of the origin on each axis) that `pick`
// selects by their world position, as sorted keys.
std::vector<std::uint64_t> inside_region(const NarrowBand& band, int reach, const std::function<bool(const Vec3d&)>& pick) {
  BandAccessor acc(band);
  const Vec3d o = (Vec3d{0, 0, 0} - band.origin()) / band.voxel_size();
  const Coord centre{int(std::lround(o.x)), int(std::lround(o.y)), int(std::lround(o.z))};
  std::vector<std::uint64_t> keys;
  for (int z = -reach; z <= reach; ++z)
    for (int y = -reach; y <= reach; ++y)
      for (int x = -reach; x <= reach; ++x) {
        const Coord c = centre + Coord{x, y, z};
        if (acc.is_inside(c) && pick(band.world(c))) keys.push_back(key_of(c));
      }
  std::sort(keys.begin(), keys.end());
  return keys;
}

TEST(CarveEuler, CuttingATorusThroughRemovesItsHandle) {
  const test::ShapeBand torus = test::make_shape_band("torus", 64);  // major radius 1, minor 0.35, axis z
  const double h = torus.band.voxel_size();
  const int reach = int(std::ceil(1.5 / h));
  BandAccessor acc(torus.band);
  // One voxel thick across the ring where it crosses x = 0, y > 0: chi 0 -> 1.
  const auto slab = inside_region(torus.band, reach, [h](const Vec3d& p) { return std::abs(p.x) < 0.5 * h && p.y > 0; });
  ASSERT_GT(slab.size(), 20u);
  EXPECT_EQ(euler_lost(acc, slab), -1);
  // Both sides (x = 0, y > 0 and y < 0): the ring falls in two, chi 0 -> 2.
  const auto two = inside_region(torus.band, reach, [h](const Vec3d& p) { return std::abs(p.x) < 0.5 * h; });
  EXPECT_EQ(euler_lost(acc, two), -2);
}

TEST(CarveEuler, DrillingThroughABallOpensATunnelAndADentChangesNothing) {
  const test::ShapeBand ball = test::make_shape_band("sphere", 48);  // radius 1
  const double h = ball.band.voxel_size();
  const int reach = int(std::ceil(1.2 / h));
  BandAccessor acc(ball.band);
  // A column through the ball along z: chi 1 -> 0 (a tunnel).
  const auto column = inside_region(ball.band, reach, [h](const Vec3d& p) {
    return std::abs(p.x) < 0.6 * h && std::abs(p.y) < 0.6 * h;
  });
  ASSERT_GT(column.size(), 30u);
  EXPECT_EQ(euler_lost(acc, column), 1);
  // The same column stopped short of the south pole: a dent from the north, chi unchanged.
  const auto dent = inside_region(ball.band, reach, [h](const Vec3d& p) {
    return std::abs(p.x) < 0.6 * h && std::abs(p.y) < 0.6 * h && p.z > 0.0;
  });
  EXPECT_EQ(euler_lost(acc, dent), 0);
  // A hollow in the middle, away from the surface: a new cavity, chi 1 -> 2.
  const auto hollow = inside_region(ball.band, reach, [](const Vec3d& p) { return length(p) < 0.4; });
  EXPECT_EQ(euler_lost(acc, hollow), -1);
}

}  // namespace
}  // namespace levelset::apps::detail
