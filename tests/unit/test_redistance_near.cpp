// redistance_near: only the bricks around the changed voxels are redistanced, and there the
// values are the whole band's redistance's; everything else stays bit for bit.
#include <gtest/gtest.h>

#include <cmath>
#include <span>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "distance/redistance.hpp"
#include "distance/redistance_near.hpp"
#include "grid/band_accessor.hpp"
#include "shape_band.hpp"

namespace levelset {
namespace {

using test::make_shape_band;

// The band with the voxels within `radius` voxels of `centre` (index space) scaled by
// `factor` (signs kept: no longer a distance there); returns the changed voxels.
std::vector<Coord> distort_ball(NarrowBand& band, const Coord& centre, int radius, float factor) {
  std::vector<Coord> changed;
  for (std::uint32_t b = 0; b < band.brick_count(); ++b) {
    const Coord o = brick_origin(band.bricks()[b].coord);
    band.update_active_in_brick(b, [&](int n, float v) {
      const Coord c = o + local_coord(n);
      const Coord d = c - centre;
      if (d.x * d.x + d.y * d.y + d.z * d.z > radius * radius) return v;
      changed.push_back(c);
      return v * factor;
    });
  }
  return changed;
}

// A voxel of the band at the zero level nearest the +x pole of the sphere.
Coord pole_voxel(const NarrowBand& band) {
  Coord best{};
  float best_x = -1e30f;
  band.for_each_active([&](const Coord& c, float v) {
    if (std::abs(v) < 0.5f * float(band.voxel_size()) && float(band.world(c).x) > best_x) {
      best_x = float(band.world(c).x);
      best = c;
    }
  });
  return best;
}

bool within_one_brick(const Coord& brick, const std::vector<Coord>& changed) {
  for (const Coord& c : changed) {
    const Coord d = brick_of(c) - brick;
    if (std::abs(d.x) <= 1 && std::abs(d.y) <= 1 && std::abs(d.z) <= 1) return true;
  }
  return false;
}

TEST(RedistanceNear, MatchesTheWholeBandsRedistanceAroundTheChangeAndKeepsTheRest) {
  const auto sb = make_shape_band("sphere", 128);
  NarrowBand in = sb.band;
  const Coord centre = pole_voxel(in);
  const std::vector<Coord> changed = distort_ball(in, centre, 3, 2.5f);
  ASSERT_GT(changed.size(), 50u);
  const NarrowBand whole = redistance(in, {}).band;
  const RedistanceNearResult near = redistance_near(in, changed, {});
  EXPECT_GT(near.bricks_redistanced, 0u);
  EXPECT_LT(near.bricks_redistanced, in.brick_count() / 10);
  ASSERT_EQ(near.band.brick_count(), in.brick_count());
  ASSERT_EQ(near.band.active_voxel_count(), in.active_voxel_count());
  BandAccessor whole_acc(whole);
  const double h = in.voxel_size();
  double worst_near = 0.0, worst_away = 0.0;
  std::size_t kept = 0, redone = 0;
  for (std::uint32_t b = 0; b < in.brick_count(); ++b) {
    ASSERT_TRUE(near.band.bricks()[b].active == in.bricks()[b].active);
    const bool local = within_one_brick(in.bricks()[b].coord, changed);
    const std::span<const float> before = in.brick_values(b), after = near.band.brick_values(b);
    std::size_t k = 0;
    in.for_each_active_in_brick(b, [&](const Coord& c, float) {
      const float u = before[k], v = after[k];
      ++k;
      ASSERT_EQ(u < 0.0f, v < 0.0f);
      if (!local) {
        kept += u == v;
        return;
      }
      ++redone;
      const std::optional<float> w = whole_acc.probe(c);
      if (w) worst_near = std::max(worst_near, std::abs(double(*w) - double(v)) / h);
      const Coord d = c - centre;
      if (d.x * d.x + d.y * d.y + d.z * d.z > 36) worst_away = std::max(worst_away, std::abs(double(v) - double(u)) / h);
    });
  }
  EXPECT_EQ(kept, in.active_voxel_count() - redone);  // bit for bit outside
  EXPECT_GT(redone, changed.size());
  // The sub-band holds every front within the band's width of the redone voxels: the same
  // values as the whole band's redistance up to the sweep's tolerance.
  EXPECT_LT(worst_near, 1e-4) << worst_near;
  // Redone voxels 3+ voxels from the distorted ball keep the distance they had.
  EXPECT_LT(worst_away, 0.01) << worst_away;
}

TEST(RedistanceNear, AFlipHeldAtEpsilonGetsItsFrontsDistance) {
  // A voxel just outside the sphere held inside at -eps (a refused flip): a new front there,
  // which the whole band's redistance and the local one see alike.
  const auto sb = make_shape_band("sphere", 96);
  NarrowBand in = sb.band;
  const Coord pole = pole_voxel(in);
  Coord held = pole;
  for (Coord c = pole; in.value(c) && *in.value(c) < 0.0f; c = c + Coord{1, 0, 0}) held = c + Coord{1, 0, 0};
  ASSERT_TRUE(in.value(held).has_value());
  ASSERT_GT(*in.value(held), 0.0f);
  in.set_value(held, float(-1e-3 * in.voxel_size()));
  const NarrowBand whole = redistance(in, {}).band;
  const NarrowBand near = redistance_near(in, {held}, {}).band;
  BandAccessor whole_acc(whole), near_acc(near);
  double worst = 0.0;
  for (int dz = -3; dz <= 3; ++dz)
    for (int dy = -3; dy <= 3; ++dy)
      for (int dx = -3; dx <= 3; ++dx) {
        const Coord c = held + Coord{dx, dy, dz};
        const auto w = whole_acc.probe(c), v = near_acc.probe(c);
        if (w && v) worst = std::max(worst, std::abs(double(*w) - double(*v)) / in.voxel_size());
      }
  EXPECT_LT(worst, 1e-4) << worst;
  EXPECT_LT(*near.value(held), 0.0f);
  // The held voxel's +x neighbour is now within about a voxel of a front, where it was farther.
  EXPECT_LT(std::abs(*near.value(held + Coord{1, 0, 0})), 1.01 * in.voxel_size());
}

TEST(RedistanceNear, ManyChangesRedistanceTheWholeBand) {
  const auto sb = make_shape_band("sphere", 64);
  NarrowBand in = sb.band;
  std::vector<Coord> all;
  in.for_each_active([&](const Coord& c, float) { all.push_back(c); });
  const RedistanceNearResult near = redistance_near(in, all, {});
  EXPECT_EQ(near.bricks_redistanced, in.brick_count());
  // The whole band's redistance, on the band's voxels (those it left beyond W at the edge).
  const NarrowBand whole = redistance(in, {}).band;
  BandAccessor whole_acc(whole);
  const float edge = float(in.half_width() * in.voxel_size());
  std::size_t same = 0, at_edge = 0, i = 0;
  in.for_each_active([&](const Coord& c, float u) {
    const float v = near.band.values()[i++];
    if (const auto w = whole_acc.probe(c)) same += *w == v;
    else at_edge += v == (u < 0.0f ? -edge : edge);
  });
  EXPECT_EQ(same + at_edge, in.active_voxel_count());
  EXPECT_LT(at_edge, in.active_voxel_count() / 100);
}

TEST(RedistanceNear, RefusesAWideBandAndAVoxelOffTheBand) {
  const auto wide = make_shape_band("sphere", 64, 10.0);
  try {
    redistance_near(wide.band, {Coord{0, 0, 0}}, {});
    FAIL() << "a half-width of 10 voxels was accepted";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::InvalidArgument);
  }
  const auto sb = make_shape_band("sphere", 64);
  try {
    redistance_near(sb.band, {Coord{100000, 0, 0}}, {});
    FAIL() << "a voxel off the band was accepted";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::InvalidArgument);
    EXPECT_NE(std::string(e.what()).find("100000"), std::string::npos) << e.what();
  }
  EXPECT_EQ(redistance_near(sb.band, {}, {}).bricks_redistanced, 0u);
}

}  // namespace
}  // namespace levelset
