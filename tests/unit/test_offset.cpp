// Offset surfaces (apps/offset.hpp, thesis 5.1.1): a sphere's radius moves by D; on the
// built-in knot and on a C-shaped ring, +D then -D is a closing (strands that merged stay
// merged), measured with genus and inside tests.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>

#include "apps/offset.hpp"
#include "apps/shape_measures.hpp"
#include "core/error.hpp"
#include "distance/redistance.hpp"
#include "geometry/analytic_shapes.hpp"
#include "grid/build_from_sdf.hpp"
#include "grid/interpolate.hpp"
#include "shape_band.hpp"

namespace levelset::apps {

namespace {

double volume_radius(double volume) { return std::cbrt(3.0 * volume / (4.0 * std::numbers::pi)); }

float value_at(const NarrowBand& band, const Vec3d& p) {
  BandAccessor acc(band);
  return sample_trilinear(acc, band, p);
}

OffsetResult offset_by(const NarrowBand& band, double d) {
  OffsetOptions o;
  o.distance = d;
  return offset_surface(band, o);
}

}  // namespace

TEST(Offset, SphereRadiusMovesByDWithinAFifthOfAVoxel) {
  const Vec3d c{0.013, -0.007, 0.011};
  const double r0 = 0.5;
  SdfBuildOptions so;
  const BBox room{c - Vec3d{0.8, 0.8, 0.8}, c + Vec3d{0.8, 0.8, 0.8}};
  so.frame = frame_for_resolution(room, 48, 3.0);
  const NarrowBand band = build_from_sdf([&](const Vec3d& p) { return length(p - c) - r0; }, room, so).band;
  const double h = band.voxel_size();
  for (double D : {0.2, -0.2}) {
    const OffsetResult r = offset_by(band, D);
    const ShapeMeasures m = measure_shape(r.band);
    const double radius = volume_radius(m.volume);
    std::printf("D %+.2f: radius %.5f expected %.5f (%.3f voxels), fitted %.5f, %d steps\n", D, radius, r0 + D,
                (radius - r0 - D) / h, m.sphere.radius, r.steps);
    EXPECT_NEAR(radius, r0 + D, 0.2 * h);
    EXPECT_NEAR(m.sphere.radius, r0 + D, 0.2 * h);
    EXPECT_EQ(r.landmine_count, 0);
  }
}

// The built-in knot is a tube of radius a = 0.15 around the (2,3) torus knot
// C(t) = ((1 + 0.4 cos 3t) cos 2t, (1 + 0.4 cos 3t) sin 2t, 0.4 sin 3t) on the torus R = 1,
// r = 0.4. C(t) and C(t + pi) lie in the same meridian half-plane (azimuth 2t + 2 pi), on
// opposite ends of a diameter of the meridian circle: the strands are 2r = 0.8 apart
// (centre to centre) along the WHOLE knot, and this is their closest approach (a numerical
// scan of |C(s) - C(t)| away from s = t finds no smaller local minimum). The tube surfaces
// are therefore 0.8 - 2a = 0.5 apart, and the central hole has radius R - r - a = 0.45.
// With 0.25 < D < 0.45 the two strands merge in every meridian plane at once, around the
// core circle (distance 0.4 from both strands), while the central hole stays open: the
// offset solid is a solid torus with a twisted, stadium-like section, genus 1 - the same
// genus as the knot, because the merge happens everywhere along the curve rather than at
// isolated points (no new handle can appear for this knot: genus cannot go UP here; the
// C-ring test below shows a merge that creates a handle). What the merge does change, and
// what -D does not undo, is the space between the strands: the core point (1, 0, 0) is
// 0.25 outside the knot, deep inside after +D, and after -D (a closing) far less outside
// than before: the webbing between the strands stays (the volume grows by more than half).
// In a meridian plane a ball of radius D can still squeeze between the dilated strands from
// the side down to about D - sqrt((a + D)^2 - r^2) = 0.05 from the core, so the core sits
// at the closing's surface (within ~1 voxel), not deep inside it. D = 0.35 is in the middle
// of (0.25, 0.45), 1.5 voxels from either end at R = 48 (h ~ 0.068); D = 0.5 closes the
// hole (genus 0). The control D = 0.2 < 0.25 does not merge: the round trip gives the knot
// back.
TEST(Offset, KnotStrandsMergeAndStayMergedAfterTheInwardOffset) {
  // W = 5 so that the band holds the core point's distance 0.25 (5 h = 0.34).
  const test::ShapeBand knot = test::make_shape_band("knot", 48, 5.0);
  const double h = knot.band.voxel_size();
  const Vec3d core{1.0, 0.0, 0.0};
  const ShapeMeasures m0 = measure_shape(knot.band);
  ASSERT_NEAR(m0.genus, 1.0, 1e-9);
  const float u0 = value_at(knot.band, core);
  EXPECT_NEAR(u0, 0.25, h);  // trilinear across the ridge between the strands reads low

  const double D = 0.35;
  const OffsetResult out = offset_by(knot.band, D);
  const ShapeMeasures m1 = measure_shape(out.band);
  const OffsetResult back = offset_by(out.band, -D);
  const ShapeMeasures m2 = measure_shape(back.band);
  std::printf("knot h %.4f: genus %.0f -> %.0f -> %.0f, components %llu -> %llu -> %llu, volume %.4f -> %.4f -> %.4f, "
              "u(core) %.3f -> %.3f -> %.3f\n",
              h, m0.genus, m1.genus, m2.genus, (unsigned long long)m0.components, (unsigned long long)m1.components,
              (unsigned long long)m2.components, m0.volume, m1.volume, m2.volume, value_at(knot.band, core),
              value_at(out.band, core), value_at(back.band, core));
  EXPECT_EQ(m1.components, 1u);
  EXPECT_NEAR(m1.genus, 1.0, 1e-9);
  EXPECT_LT(value_at(out.band, core), -2 * h);  // merged: the core circle is inside
  EXPECT_EQ(m2.components, 1u);
  EXPECT_NEAR(m2.genus, 1.0, 1e-9);
  EXPECT_LT(value_at(back.band, core), u0 - 2 * h);  // the gap stays filled to within ~1 voxel
  EXPECT_GT(m2.volume, 1.5 * m0.volume);        // the webbing between the strands stayed

  // Control: D = 0.2 < 0.25 does not merge; the round trip gives the knot back.
  const OffsetResult small = offset_by(offset_by(knot.band, 0.2).band, -0.2);
  const ShapeMeasures ms = measure_shape(small.band);
  EXPECT_NEAR(value_at(small.band, core), u0, 0.25 * h);
  EXPECT_NEAR(ms.genus, 1.0, 1e-9);
  EXPECT_NEAR(ms.volume / m0.volume, 1.0, 0.05);
}

// A C-shaped ring: the torus (R = 1, r = 0.25) minus the box |x - 1| < 0.5, |y| < 0.15:
// genus 0, its two cut faces 0.3 apart. +D with D = 0.25 > 0.15 joins the ends (a handle
// appears: genus 0 -> 1); -D does not reopen the gap (0.3 < 2D): genus stays 1.
TEST(Offset, CRingClosesIntoARingAndStaysClosed) {
  const auto torus = make_torus({0, 0, 0}, 1.0, 0.25);
  const auto cut = make_box({1.0, 0, 0}, {0.5, 0.15, 0.5});
  auto sdf = [&](const Vec3d& p) { return std::max(torus->distance(p), -cut->distance(p)); };
  SdfBuildOptions so;
  so.frame = frame_for_resolution(torus->bounds(), 64, 3.0);
  const NarrowBand band = redistance(build_from_sdf(sdf, torus->bounds(), so).band, {}).band;
  const ShapeMeasures m0 = measure_shape(band);
  const OffsetResult out = offset_by(band, 0.25);
  const ShapeMeasures m1 = measure_shape(out.band);
  const ShapeMeasures m2 = measure_shape(offset_by(out.band, -0.25).band);
  std::printf("C-ring: genus %.0f -> %.0f -> %.0f, volume %.4f -> %.4f -> %.4f\n", m0.genus, m1.genus, m2.genus,
              m0.volume, m1.volume, m2.volume);
  EXPECT_NEAR(m0.genus, 0.0, 1e-9);
  EXPECT_NEAR(m1.genus, 1.0, 1e-9);
  EXPECT_NEAR(m2.genus, 1.0, 1e-9);
  EXPECT_EQ(m2.components, 1u);
}

TEST(Offset, RejectsBadDistances) {
  const test::ShapeBand s = test::make_shape_band("sphere", 24);
  for (double d : {0.0, std::nan(""), 1e9}) {
    OffsetOptions o;
    o.distance = d;
    EXPECT_THROW(offset_surface(s.band, o), Error) << d;
  }
}

}  // namespace levelset::apps
