// guard_topology (grid/topology_guard.hpp): sign changes that would change the topology of
// the inside set are refused, simple ones pass, and ambiguous faces keep their decision.
#include <gtest/gtest.h>

#include <cmath>
#include <optional>

#include "core/error.hpp"
#include "grid/build_from_sdf.hpp"
#include "grid/sign_components.hpp"
#include "grid/topology_guard.hpp"
#include "surface/marching_cubes.hpp"
#include "surface/mesh_measures.hpp"

namespace levelset {
namespace {

NarrowBand band_of(const std::function<double(const Vec3d&)>& sdf, double lo, double hi, double h,
                   double half_width = 3.0) {
  SdfBuildOptions o;
  o.frame = GridFrame{h, Vec3d{0, 0, 0}, half_width};
  BBox b;
  b.min = {lo, lo, lo};
  b.max = {hi, hi, hi};
  return build_from_sdf(sdf, b, o).band;
}

std::vector<float> values_of(const NarrowBand& band) { return {band.values().begin(), band.values().end()}; }

std::size_t inside_components(const NarrowBand& band) {
  std::size_t n = 0;
  for (const SignComponent& c : sign_components(band).components) n += c.inside ? 1 : 0;
  return n;
}

TEST(SimpleVoxel, FlatFaceIsSimpleAndIsolatedVoxelOrTunnelIsNot) {
  auto bit = [](int dx, int dy, int dz) { return 1u << ((dz + 1) * 9 + (dy + 1) * 3 + dx + 1); };
  std::uint32_t below = 0;  // the half space z < 0 inside
  for (int dy = -1; dy <= 1; ++dy)
    for (int dx = -1; dx <= 1; ++dx) below |= bit(dx, dy, -1);
  EXPECT_TRUE(simple_voxel(below));
  EXPECT_FALSE(simple_voxel(0u));                            // a lone voxel: flipping deletes a component
  EXPECT_FALSE(simple_voxel(bit(0, 0, -1) | bit(0, 0, 1)));  // the middle of a 1-voxel rod: flipping cuts it
  std::uint32_t ring = 0;  // a ring round the centre in the z = 0 plane: filling it closes a hole
  for (int dy = -1; dy <= 1; ++dy)
    for (int dx = -1; dx <= 1; ++dx)
      if (dx != 0 || dy != 0) ring |= bit(dx, dy, 0);
  EXPECT_FALSE(simple_voxel(ring));
}

TEST(TopologyGuard, ThinSlabIsNotCutButMayMoveWhereSimple) {
  // A slab one voxel thick (|z| < 0.5 h) proposed to move wholly outside: every flip would cut
  // or delete it, so all sign changes that would remove its last voxel row are refused and the
  // slab stays one component.
  const double h = 0.1;
  const NarrowBand slab = band_of([&](const Vec3d& p) { return std::max(std::abs(p.z) - 0.5 * h, std::max(std::abs(p.x), std::abs(p.y)) - 1.0); }, -1.5, 1.5, h);
  ASSERT_EQ(inside_components(slab), 1u);
  std::vector<float> proposed = values_of(slab);
  for (float& v : proposed) v = std::abs(v) + 0.01f;  // everything outside
  TopologyGuardOptions o;
  o.eps = 1e-3 * h;
  TopologyGuardResult r = guard_topology(slab, slab, proposed, o);
  EXPECT_GT(r.refused_flips, 0u);
  NarrowBand kept = slab;
  kept.swap_values(r.values);
  EXPECT_EQ(inside_components(kept), 1u);
  // The same proposal with every voxel free: the slab vanishes.
  o.free = [](const Coord&) { return true; };
  r = guard_topology(slab, slab, proposed, o);
  EXPECT_EQ(r.refused_flips, 0u);
  NarrowBand gone = slab;
  gone.swap_values(r.values);
  EXPECT_EQ(inside_components(gone), 0u);
}

TEST(TopologyGuard, GrowingABallIsSimpleEverywhere) {
  // A ball grown by half a voxel: every flip is simple (outside voxels next to the front join
  // the inside one shell at a time), none is refused.
  const NarrowBand ball = band_of([](const Vec3d& p) { return length(p) - 0.6; }, -1.0, 1.0, 0.1);
  std::vector<float> proposed = values_of(ball);
  for (float& v : proposed) v -= 0.05f;
  TopologyGuardOptions o;
  o.eps = 1e-4;
  const TopologyGuardResult r = guard_topology(ball, ball, proposed, o);
  EXPECT_EQ(r.refused_flips, 0u);
  EXPECT_EQ(r.values, proposed);
}

TEST(TopologyGuard, PinnedThinVoxelsStayWhereSimpleFlipsWouldErodeTheSheet) {
  // A disc one voxel thick, proposed to go wholly outside. Each flip at its rim is simple, so
  // the guard alone lets it erode to its last voxel; pinned voxels where it is thin stay.
  const double h = 0.1;
  auto disc = [&](const Vec3d& p) { return std::max(std::abs(p.z) - 0.5 * h, std::hypot(p.x, p.y) - 0.8); };
  const NarrowBand band = band_of(disc, -1.2, 1.2, h);
  std::vector<float> proposed = values_of(band);
  for (float& v : proposed) v = std::abs(v) + 0.01f;
  auto inside_count = [](const std::vector<float>& values) {
    std::size_t n = 0;
    for (float v : values) n += v < 0.0f;
    return n;
  };
  const std::size_t before = inside_count(values_of(band));
  ASSERT_GT(before, 150u);
  TopologyGuardOptions o;
  o.eps = 1e-3 * h;
  const TopologyGuardResult eroded = guard_topology(band, band, proposed, o);
  EXPECT_LT(inside_count(eroded.values), before / 10);
  o.pinned = [](const Coord& c) { return c.x >= 0; };  // half of it holds data
  const TopologyGuardResult kept = guard_topology(band, band, proposed, o);
  const std::size_t left = inside_count(kept.values);
  EXPECT_GE(left, before / 2 - 10);
  EXPECT_LT(left, before);
}

TEST(TopologyGuard, AmbiguousFaceKeepsItsDecision) {
  // Two balls whose insides meet only across a face diagonal at the origin's face: before,
  // the face's inside corners are joined (v00 v11 > v10 v01); the proposal keeps all signs but
  // makes the outside corners deeper, which would separate them. The guard restores the face.
  const double h = 1.0;
  NarrowBand band = band_of([](const Vec3d& p) {
    const double a = length(p - Vec3d{-0.7, -0.7, 0}) - 0.8, b = length(p - Vec3d{1.7, 1.7, 0}) - 0.8;
    return std::min(a, b);
  }, -3, 4, h);
  // Voxels (0,0,0) and (1,1,0) inside, (1,0,0) and (0,1,0) outside: set them explicitly.
  band.set_value({0, 0, 0}, -0.5f);
  band.set_value({1, 1, 0}, -0.5f);
  band.set_value({1, 0, 0}, 0.2f);
  band.set_value({0, 1, 0}, 0.2f);
  std::vector<float> proposed = values_of(band);
  NarrowBand changed = band;
  changed.set_value({1, 0, 0}, 0.9f);
  changed.set_value({0, 1, 0}, 0.9f);
  proposed = values_of(changed);
  TopologyGuardOptions o;
  o.eps = 1e-3;
  const TopologyGuardResult r = guard_topology(band, band, proposed, o);
  EXPECT_GT(r.restored_values, 0u);
  NarrowBand kept = band;
  std::vector<float> values = r.values;
  kept.swap_values(values);
  EXPECT_FLOAT_EQ(*kept.value({1, 0, 0}), 0.2f);
  EXPECT_FLOAT_EQ(*kept.value({0, 1, 0}), 0.2f);
}

// Face neighbours of opposite sign where one is not active (the band invariant's breaches),
// over the active voxels' box grown by 2.
std::size_t invariant_breaches(const NarrowBand& band) {
  const IndexBox box = band.active_index_bounds();
  std::size_t breaches = 0;
  for (int z = box.min.z - 2; z <= box.max.z + 2; ++z)
    for (int y = box.min.y - 2; y <= box.max.y + 2; ++y)
      for (int x = box.min.x - 2; x <= box.max.x + 2; ++x) {
        const Coord c{x, y, z};
        for (const Coord& n : {Coord{x + 1, y, z}, Coord{x, y + 1, z}, Coord{x, y, z + 1}})
          if (band.is_inside(c) != band.is_inside(n) && !(band.is_active(c) && band.is_active(n))) ++breaches;
      }
  return breaches;
}

TEST(TopologyGuard, AComponentTheNewBandLeftVanishesWithoutBreakingTheBand) {
  // An evolve step can remove a component smaller than the band. Here a rod one voxel thick
  // runs along z beside a sphere: its middle voxel lies inside the sphere's band, its other
  // voxels just outside it. Keeping the middle voxel inside (the rod's last voxel) would
  // leave it next to voxels that are inactive and outside in `after`, which no value can
  // repair: the flip is taken (forced) and the band invariant holds.
  const double h = 0.1;
  auto sphere = [](const Vec3d& p) { return length(p) - 1.0015; };
  auto rod = [](const Vec3d& p) {
    return length(Vec3d{p.x - 1.3, p.y, std::max(0.0, std::abs(p.z) - 0.25)}) - 0.05;
  };
  auto both = [&](const Vec3d& p) { return std::min(sphere(p), rod(p)); };
  const NarrowBand before = band_of(both, -1.6, 1.6, h);
  const NarrowBand after = band_of(sphere, -1.6, 1.6, h);
  ASSERT_EQ(inside_components(before), 2u);
  ASSERT_TRUE(before.is_inside({13, 0, 2}) && before.is_inside({13, 0, -2}));
  ASSERT_TRUE(after.is_active({13, 0, 0}));   // 2.985 voxels off the sphere: in its band
  ASSERT_FALSE(after.is_active({13, 0, 1}));  // 3.02 voxels off: not
  TopologyGuardOptions o;
  o.eps = 1e-3 * h;
  const TopologyGuardResult r = guard_topology(before, after, values_of(after), o);
  EXPECT_EQ(r.forced_flips, 1u);
  NarrowBand kept = after;
  std::vector<float> values = r.values;
  kept.swap_values(values);
  EXPECT_EQ(invariant_breaches(kept), 0u);
  EXPECT_EQ(inside_components(kept), 1u);
  // The same change in a band that holds the whole rod is refused as usual.
  const TopologyGuardResult w = guard_topology(band_of(both, -1.6, 1.6, h, 6.0), band_of(sphere, -1.6, 1.6, h, 6.0),
                                               values_of(band_of(sphere, -1.6, 1.6, h, 6.0)), o);
  EXPECT_EQ(w.forced_flips, 0u);
  EXPECT_GT(w.refused_flips, 0u);
}

TEST(TopologyGuard, MismatchedInputsGiveTypedErrors) {
  const NarrowBand ball = band_of([](const Vec3d& p) { return length(p) - 0.6; }, -1.0, 1.0, 0.1);
  const NarrowBand finer = band_of([](const Vec3d& p) { return length(p) - 0.6; }, -1.0, 1.0, 0.05);
  auto code = [](auto&& call) -> std::optional<ErrorCode> {
    try {
      call();
    } catch (const Error& e) {
      return e.code();
    }
    return std::nullopt;
  };
  TopologyGuardOptions o;
  o.eps = 1e-3;
  std::vector<float> short_values(ball.active_voxel_count() - 1, 1.0f);
  EXPECT_EQ(code([&] { guard_topology(ball, ball, short_values, o); }), ErrorCode::InvalidArgument);
  EXPECT_EQ(code([&] { guard_topology(ball, finer, values_of(finer), o); }), ErrorCode::InvalidArgument);
  // eps = 0 would give a refused inside voxel the value -0, which reads as outside.
  EXPECT_EQ(code([&] { guard_topology(ball, ball, values_of(ball), TopologyGuardOptions{}); }), ErrorCode::InvalidArgument);
}

TEST(TopologyGuard, FreeFlipsOfAWholeFaceAreNotUndone) {
  // Every corner of an alternating face flips (allowed: free): the face alternates about the
  // other diagonal, its decision is no comparison with the old one, and no sign may be restored.
  const NarrowBand band = band_of([](const Vec3d& p) { return length(p) - 0.6; }, -1.0, 1.0, 0.1);
  NarrowBand checker = band;
  checker.set_value({0, 0, 0}, -0.5f * 0.1f);
  checker.set_value({1, 1, 0}, -0.5f * 0.1f);
  checker.set_value({1, 0, 0}, 0.2f * 0.1f);
  checker.set_value({0, 1, 0}, 0.2f * 0.1f);
  NarrowBand swapped = checker;
  swapped.set_value({0, 0, 0}, 0.5f * 0.1f);
  swapped.set_value({1, 1, 0}, 0.5f * 0.1f);
  swapped.set_value({1, 0, 0}, -0.2f * 0.1f);
  swapped.set_value({0, 1, 0}, -0.2f * 0.1f);
  TopologyGuardOptions o;
  o.eps = 1e-4;
  o.free = [](const Coord&) { return true; };
  const TopologyGuardResult r = guard_topology(checker, checker, values_of(swapped), o);
  EXPECT_EQ(r.refused_flips, 0u);
  EXPECT_EQ(r.values, values_of(swapped));
}

TEST(CuttingVoxel, CutsAndDropsPassTunnelsAndCavitiesDoNot) {
  auto bit = [](int dx, int dy, int dz) { return 1u << ((dz + 1) * 9 + (dy + 1) * 3 + dx + 1); };
  std::uint32_t below = 0;
  for (int dy = -1; dy <= 1; ++dy)
    for (int dx = -1; dx <= 1; ++dx) below |= bit(dx, dy, -1);
  EXPECT_TRUE(cutting_voxel(below));  // simple flips cut nothing, and pass too
  EXPECT_TRUE(cutting_voxel(bit(0, 0, -1) | bit(0, 0, 1)));  // a rod's middle: the rod is cut
  EXPECT_TRUE(cutting_voxel(0u));                            // a lone voxel is dropped
  std::uint32_t disc = 0;  // the centre of a one-voxel plate: turning it outside opens a hole
  for (int dy = -1; dy <= 1; ++dy)
    for (int dx = -1; dx <= 1; ++dx)
      if (dx != 0 || dy != 0) disc |= bit(dx, dy, 0);
  EXPECT_FALSE(cutting_voxel(disc));
  EXPECT_FALSE(cutting_voxel((1u << 27) - 1u));  // buried: a cavity
}

double genus_of(const NarrowBand& band) {
  return measure_mesh(marching_cubes(band).mesh).genus;
}

TEST(TopologyGuard, CuttableVoxelsCutARingButNeverPunchAPlate) {
  // A ring (torus, tube 2-3 voxels thick) proposed outside across one section: the guard alone
  // refuses the last flips that would cut it; where the section is cuttable it is cut (one
  // arc left, genus 0), and nothing else changes.
  const double h = 0.1;
  const NarrowBand ring =
      band_of([](const Vec3d& p) { return std::hypot(std::hypot(p.x, p.y) - 0.6, p.z) - 0.13; },
              -1.0, 1.0, h);
  ASSERT_EQ(genus_of(ring), 1.0);
  std::vector<float> proposed = values_of(ring);
  std::size_t i = 0;
  ring.for_each_active_world([&](const Coord&, const Vec3d& p, float v) {
    if (p.x > 0.45 && std::abs(p.y) < 0.25) proposed[i] = std::abs(v) + 0.01f;
    ++i;
  });
  TopologyGuardOptions o;
  o.eps = 1e-3 * h;
  NarrowBand kept = ring;
  std::vector<float> values = guard_topology(ring, ring, proposed, o).values;
  kept.swap_values(values);
  EXPECT_EQ(genus_of(kept), 1.0);
  o.cuttable = [](const Coord&) { return true; };
  NarrowBand cut = ring;
  values = guard_topology(ring, ring, proposed, o).values;
  cut.swap_values(values);
  EXPECT_EQ(genus_of(cut), 0.0);
  EXPECT_EQ(inside_components(cut), 1u);
  // A plate two voxels thick proposed outside in a patch of its middle: cutting flips would
  // have to open a hole through it (a tunnel), which rule 1b never takes.
  const NarrowBand plate = band_of(
      [](const Vec3d& p) {
        return std::max(std::abs(p.z) - 0.1, std::max(std::abs(p.x), std::abs(p.y)) - 0.7);
      },
      -1.0, 1.0, h);
  ASSERT_EQ(genus_of(plate), 0.0);
  proposed = values_of(plate);
  i = 0;
  plate.for_each_active_world([&](const Coord&, const Vec3d& p, float v) {
    if (std::abs(p.x) < 0.25 && std::abs(p.y) < 0.25) proposed[i] = std::abs(v) + 0.01f;
    ++i;
  });
  NarrowBand punched = plate;
  TopologyGuardResult r = guard_topology(plate, plate, proposed, o);
  EXPECT_GT(r.refused_flips, 0u);
  punched.swap_values(r.values);
  EXPECT_EQ(genus_of(punched), 0.0);
  EXPECT_EQ(inside_components(punched), 1u);
}

}  // namespace
}  // namespace levelset
