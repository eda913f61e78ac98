// Cuts through the inside after a sheet was found (reconstruction_parts.hpp cutting_reach,
// drop_web_scraps): the snaps may cut only the flips connected to the sheet's zone, and the
// scraps a double cut leaves are turned outside.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <vector>

#include "apps/reconstruction_parts.hpp"
#include "grid/build_from_sdf.hpp"
#include "grid/sign_components.hpp"
#include "grid/topology_guard.hpp"
#include "surface/marching_cubes.hpp"
#include "surface/mesh_measures.hpp"

namespace levelset::apps::detail {
namespace {

constexpr double kH = 0.1;

// A ring (torus of tube radius 1.3 voxels) round the z axis.
NarrowBand ring_band() {
  SdfBuildOptions o;
  o.frame = GridFrame{kH, Vec3d{0, 0, 0}, 3.0};
  BBox b;
  b.min = {-1, -1, -1};
  b.max = {1, 1, 1};
  return build_from_sdf(
             [](const Vec3d& p) { return std::hypot(std::hypot(p.x, p.y) - 0.6, p.z) - 0.13; }, b,
             o)
      .band;
}

// The band's values with the voxels where `out` holds proposed outside.
std::vector<float> proposed(const NarrowBand& band, const std::function<bool(const Vec3d&)>& out) {
  std::vector<float> v(band.values().begin(), band.values().end());
  std::size_t i = 0;
  band.for_each_active_world([&](const Coord&, const Vec3d& p, float value) {
    if (out(p)) v[i] = std::abs(value) + 0.01f;
    ++i;
  });
  return v;
}

std::vector<std::uint64_t> zone_at(const NarrowBand& band, const Vec3d& p) {
  const Coord c{int(std::lround((p.x - band.origin().x) / kH)),
                int(std::lround((p.y - band.origin().y) / kH)),
                int(std::lround((p.z - band.origin().z) / kH))};
  std::vector<std::uint64_t> zone;
  for (int d = 0; d < 27; ++d)
    zone.push_back(key_of(c + Coord{d % 3 - 1, (d / 3) % 3 - 1, d / 9 - 1}));
  std::sort(zone.begin(), zone.end());
  return zone;
}

NarrowBand guarded(const NarrowBand& band, std::vector<float> next,
                   const std::vector<std::uint64_t>& cuttable) {
  TopologyGuardOptions o;
  o.eps = 1e-3 * kH;
  if (!cuttable.empty())
    o.cuttable = [&](const Coord& c) {
      return std::binary_search(cuttable.begin(), cuttable.end(), key_of(c));
    };
  std::vector<float> values = guard_topology(band, band, std::move(next), o).values;
  NarrowBand out = band;
  out.swap_values(values);
  return out;
}

double genus_of(const NarrowBand& band) {
  return measure_mesh(marching_cubes(band).mesh).genus;
}

std::size_t inside_components(const NarrowBand& band) {
  std::size_t n = 0;
  for (const SignComponent& c : sign_components(band).components) n += c.inside ? 1 : 0;
  return n;
}

TEST(CuttingReach, OnlyTheFlipsConnectedToTheZoneMayCut) {
  const NarrowBand ring = ring_band();
  ASSERT_EQ(genus_of(ring), 1.0);
  // Two sections of the ring proposed outside, at +x and -x; the zone touches the +x one.
  auto plus = [](const Vec3d& p) { return p.x > 0.45 && std::abs(p.y) < 0.25; };
  auto minus = [](const Vec3d& p) { return p.x < -0.45 && std::abs(p.y) < 0.25; };
  const std::vector<float> next =
      proposed(ring, [&](const Vec3d& p) { return plus(p) || minus(p); });
  const std::vector<std::uint64_t> reach =
      cutting_reach(ring, next, zone_at(ring, {0.6, 0.0, 0.0}));
  std::size_t leaving_plus = 0, reached_plus = 0, reached_minus = 0;
  ring.for_each_active_world([&](const Coord& c, const Vec3d& p, float v) {
    const bool reached = std::binary_search(reach.begin(), reach.end(), key_of(c));
    if (v < 0.0f && plus(p)) {
      ++leaving_plus;
      reached_plus += reached;
    }
    if (minus(p)) reached_minus += reached;
    if (v >= 0.0f) {
      EXPECT_FALSE(reached);  // only voxels that would leave the inside
    }
  });
  EXPECT_GT(leaving_plus, 20u);
  EXPECT_EQ(reached_plus, leaving_plus);
  EXPECT_EQ(reached_minus, 0u);
  // The guard cuts the ring at +x only: one arc, no handle.
  const NarrowBand cut = guarded(ring, next, reach);
  EXPECT_EQ(genus_of(cut), 0.0);
  EXPECT_EQ(inside_components(cut), 1u);
  // With no zone nothing is cut.
  EXPECT_EQ(genus_of(guarded(ring, next, cutting_reach(ring, next, {}))), 1.0);
}

TEST(CuttingReach, TheScrapBetweenTwoCutsIsDropped) {
  const NarrowBand ring = ring_band();
  // Two cuts two voxels apart at +x: the piece between them (a few voxels) is a scrap.
  const std::vector<float> next = proposed(ring, [](const Vec3d& p) {
    return p.x > 0.45 && std::abs(p.y) > 0.1 && std::abs(p.y) < 0.3;
  });
  std::vector<std::uint64_t> zone = zone_at(ring, {0.6, 0.2, 0.0}),
                             other = zone_at(ring, {0.6, -0.2, 0.0});
  zone.insert(zone.end(), other.begin(), other.end());
  std::sort(zone.begin(), zone.end());
  const std::vector<std::uint64_t> reach = cutting_reach(ring, next, zone);
  NarrowBand cut = guarded(ring, next, reach);
  EXPECT_EQ(inside_components(cut), 2u);  // the arc and the scrap
  drop_web_scraps(cut, reach);
  EXPECT_EQ(inside_components(cut), 1u);
  EXPECT_EQ(genus_of(cut), 0.0);
}

}  // namespace
}  // namespace levelset::apps::detail
