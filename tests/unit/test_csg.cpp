// CSG (apps/csg.hpp, thesis 3.5, 5.1.4, Table 3.1): two overlapping spheres against the
// analytic lens volumes, with equal and with different voxel sizes and origins; signs far
// from both bands; seam fairing smooths the crease and leaves the far surface alone.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>

#include "apps/band_curvature.hpp"
#include "apps/csg.hpp"
#include "apps/shape_measures.hpp"
#include "core/error.hpp"
#include "grid/build_from_sdf.hpp"
#include "grid/interpolate.hpp"
#include "surface/marching_cubes.hpp"

namespace levelset::apps {

namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kR = 0.5, kD = 0.6;  // radius, centre distance
const Vec3d kCa{-0.3 + 0.013, -0.007, 0.011}, kCb{0.3 + 0.013, -0.007, 0.011};

// Volume of the lens where two balls of radius r at distance d overlap.
double lens_volume(double r, double d) { return kPi * (4 * r + d) * (2 * r - d) * (2 * r - d) / 12.0; }
double ball_volume(double r) { return 4.0 / 3.0 * kPi * r * r * r; }

NarrowBand sphere_band(const Vec3d& c, double h, const Vec3d& origin, double half_width) {
  SdfBuildOptions o;
  o.frame.voxel_size = h;
  o.frame.origin = origin;
  o.frame.half_width = half_width;
  return build_from_sdf([c](const Vec3d& p) { return length(p - c) - kR; },
                        BBox{c - Vec3d{kR, kR, kR}, c + Vec3d{kR, kR, kR}}, o)
      .band;
}

float value_at(const NarrowBand& band, const Vec3d& p) {
  BandAccessor acc(band);
  return sample_trilinear(acc, band, p);
}

}  // namespace

TEST(Csg, OverlappingSpheresMatchTheLensVolumes) {
  const double h = 1.6 / 48;  // 48 voxels over the pair
  const Vec3d origin{-1.0, -0.8, -0.8};
  const NarrowBand a = sphere_band(kCa, h, origin, 3.0), b = sphere_band(kCb, h, origin, 3.0);
  const double lens = lens_volume(kR, kD), ball = ball_volume(kR);
  struct Case {
    CsgOp op;
    double volume;
  };
  for (const Case c : {Case{CsgOp::Union, 2 * ball - lens}, Case{CsgOp::Intersection, lens},
                       Case{CsgOp::Difference, ball - lens}}) {
    CsgOptions o;
    o.op = c.op;
    const CsgResult r = csg(a, b, o);
    const ShapeMeasures m = measure_shape(r.band);
    std::printf("%s: volume %.5f expected %.5f (%.2f%%), components %llu genus %.0f, %llu candidate bricks\n",
                std::string(csg_op_name(c.op)).c_str(), m.volume, c.volume, 100 * (m.volume / c.volume - 1),
                (unsigned long long)m.components, m.genus, (unsigned long long)r.candidate_bricks);
    EXPECT_NEAR(m.volume / c.volume, 1.0, 0.01) << csg_op_name(c.op);
    EXPECT_EQ(m.components, 1u);
    EXPECT_NEAR(m.genus, 0.0, 1e-9);
    EXPECT_TRUE(m.watertight);
    EXPECT_DOUBLE_EQ(r.band.voxel_size(), h);
    EXPECT_DOUBLE_EQ(r.band.half_width(), 3.0);
    // Signs away from both bands: the centres (inside A only, inside B only) and far points.
    const bool in_a = c.op != CsgOp::Intersection;  // A's centre is outside B
    const bool in_b = c.op == CsgOp::Union;
    EXPECT_EQ(value_at(r.band, kCa - Vec3d{0.2, 0, 0}) < 0, in_a) << csg_op_name(c.op);
    EXPECT_EQ(value_at(r.band, kCb + Vec3d{0.2, 0, 0}) < 0, in_b) << csg_op_name(c.op);
    EXPECT_GT(value_at(r.band, {5, 5, 5}), 0.0f);
    EXPECT_GT(value_at(r.band, {-5, 0, 0}), 0.0f);
  }
}

TEST(Csg, DifferentVoxelSizesAndOriginsResampleToTheFinerGrid) {
  const double h = 1.6 / 48;
  const NarrowBand a = sphere_band(kCa, h, {-1.0, -0.8, -0.8}, 3.0);
  const NarrowBand b = sphere_band(kCb, 1.5 * h, {-0.71, -0.83, -0.77}, 3.0);
  const double lens = lens_volume(kR, kD), ball = ball_volume(kR);
  for (CsgOp op : {CsgOp::Union, CsgOp::Intersection, CsgOp::Difference}) {
    CsgOptions o;
    o.op = op;
    const CsgResult r = csg(b, a, o);  // the finer one second: its frame is chosen anyway
    EXPECT_DOUBLE_EQ(r.band.voxel_size(), h);
    EXPECT_EQ(r.band.origin(), a.origin());
    const ShapeMeasures m = measure_shape(r.band);
    const double expected = op == CsgOp::Union ? 2 * ball - lens : (op == CsgOp::Intersection ? lens : ball - lens);
    std::printf("%s (B minus A for difference), mixed h: volume %.5f expected %.5f (%.2f%%)\n",
                std::string(csg_op_name(op)).c_str(), m.volume, expected, 100 * (m.volume / expected - 1));
    EXPECT_NEAR(m.volume / expected, 1.0, 0.015) << csg_op_name(op);
    EXPECT_EQ(m.components, 1u);
    EXPECT_NEAR(m.genus, 0.0, 1e-9);
  }
  // An explicit, coarser voxel size.
  CsgOptions o;
  o.voxel_size = 2 * h;
  const CsgResult r = csg(a, b, o);
  EXPECT_DOUBLE_EQ(r.band.voxel_size(), 2 * h);
  EXPECT_NEAR(measure_shape(r.band).volume / (2 * ball - lens), 1.0, 0.03);
}

TEST(Csg, SeamFairingSmoothsTheCreaseAndLeavesTheFarSurface) {
  const double h = 1.6 / 48;
  const Vec3d origin{-1.0, -0.8, -0.8};
  const NarrowBand a = sphere_band(kCa, h, origin, 5.0), b = sphere_band(kCb, h, origin, 5.0);
  CsgOptions o;
  o.op = CsgOp::Union;
  const CsgResult sharp = csg(a, b, o);
  o.seam_radius = 2 * h;
  o.seam_time = 3 * h * h;
  const CsgResult faired = csg(a, b, o);
  ASSERT_GT(faired.seam_steps, 0);
  // The crease is the circle x = 0.013, radius sqrt(r^2 - (d/2)^2) = 0.4: the union is
  // concave there (H very negative). Compare the extreme H over vertices within 2 h of it.
  const TriangleMesh before = marching_cubes(sharp.band).mesh, after = marching_cubes(faired.band).mesh;
  auto seam_min_h = [&](const NarrowBand& band, const TriangleMesh& mesh) {
    BandAccessor acc(band);
    double lowest = 0;
    for (const Vec3d& v : mesh.vertices)
      if (std::abs(v.x - kCa.x - 0.3) < 2 * h) lowest = std::min(lowest, band_mean_curvature(acc, band, v));
    return lowest;
  };
  const double h0 = seam_min_h(sharp.band, before), h1 = seam_min_h(faired.band, after);
  // Far from the seam (outside the region of influence) the surface must not move.
  double far_move = 0;
  int far_count = 0;
  for (const Vec3d& v : before.vertices) {
    if (seam_region_of_influence(a, b, o.seam_radius, v) > 0) continue;
    far_move = std::max(far_move, double(std::abs(value_at(faired.band, v))));
    ++far_count;
  }
  const double v0 = measure_shape(sharp.band).volume, v1 = measure_shape(faired.band).volume;
  std::printf("seam: min H %.2f -> %.2f (1/h = %.1f), far vertices %d moved <= %.4f voxels, volume %.5f -> %.5f, "
              "%d steps\n",
              h0, h1, 1 / h, far_count, far_move / h, v0, v1, faired.seam_steps);
  EXPECT_GT(h1, 0.5 * h0);  // the crease's |H| at least halves (H < 0 there)
  EXPECT_GT(far_count, int(before.vertices.size() / 2));
  EXPECT_LT(far_move, 0.1 * h);
  EXPECT_GT(v1, v0);  // filling a concave crease adds volume
}

TEST(Csg, RejectsBadOptions) {
  const double h = 1.6 / 24;
  const NarrowBand a = sphere_band(kCa, h, {-1.0, -0.8, -0.8}, 3.0);
  CsgOptions bad_h;
  bad_h.voxel_size = -1;
  EXPECT_THROW(csg(a, a, bad_h), Error);
  CsgOptions fine;
  fine.voxel_size = 1e-5;  // ~10^12 bricks
  EXPECT_THROW(csg(a, a, fine), Error);
  CsgOptions no_radius;
  no_radius.seam_time = 0.01;
  EXPECT_THROW(csg(a, a, no_radius), Error);
  EXPECT_THROW(csg_op_from_name("xor"), Error);
}

}  // namespace levelset::apps
