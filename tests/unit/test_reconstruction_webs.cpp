// Tunnels through webs (reconstruction_parts.hpp open_web_tunnels): a sheet of the inside
// that spans a handle's hole and lies on no point is cut, which opens the handle; a part's
// interior beside a hole in the sampling, and a sheet the points sample, stay. The fine pass
// opens a hole narrower than the clearance through a thin plate, whose wall's points lie in
// the plug below the surface, and leaves a plate whose sampling has a hole of the same size.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

#include "apps/reconstruction_parts.hpp"
#include "apps/shape_measures.hpp"
#include "grid/band_accessor.hpp"
#include "grid/build_from_sdf.hpp"

namespace levelset::apps::detail {
namespace {

constexpr double kMajor = 1.0, kMinor = 0.35;  // the torus, axis z

double torus_distance(const Vec3d& p) {
  const double rho = std::sqrt(p.x * p.x + p.y * p.y);
  return std::hypot(rho - kMajor, p.z) - kMinor;
}

// The band at resolution 64 of the torus with its hole filled by a disk in z = 0 of
// half-thickness `half_thickness` (a web, as the start shell leaves across a handle).
NarrowBand webbed_torus(double half_thickness) {
  BBox box;
  box.extend({-kMajor - kMinor, -kMajor - kMinor, -kMinor});
  box.extend({kMajor + kMinor, kMajor + kMinor, kMinor});
  SdfBuildOptions options;
  options.frame = frame_for_resolution(box, 64, 3.0);
  auto sdf = [half_thickness](const Vec3d& p) {
    const double disk = std::max(std::abs(p.z) - half_thickness, std::sqrt(p.x * p.x + p.y * p.y) - kMajor);
    return std::min(torus_distance(p), disk);
  };
  return build_from_sdf(sdf, box, options).band;
}

// Points on the torus's surface, spacing ~0.016 (a third of the grid's voxel).
std::vector<Vec3d> torus_points() {
  std::vector<Vec3d> p;
  const int nu = 400, nv = 150;
  for (int i = 0; i < nu; ++i)
    for (int j = 0; j < nv; ++j) {
      const double u = 2 * std::numbers::pi * i / nu, v = 2 * std::numbers::pi * j / nv;
      const double rho = kMajor + kMinor * std::cos(v);
      p.push_back({rho * std::cos(u), rho * std::sin(u), kMinor * std::sin(v)});
    }
  return p;
}

WebTunnelSettings settings(double h) {
  WebTunnelSettings s;
  s.clearance = 2.0 * h;
  s.lining_depth = 1.5 * h;
  return s;
}

bool inside_at(const NarrowBand& band, const Vec3d& x) {
  BandAccessor acc(band);
  const Vec3d q = band.to_index_space(x);
  return acc.is_inside(Coord{int(std::lround(q.x)), int(std::lround(q.y)), int(std::lround(q.z))});
}

TEST(WebTunnels, CuttingTheWebAcrossATorussHoleOpensItsHandle) {
  NarrowBand band = webbed_torus(0.03);
  const double h = band.voxel_size();
  ASSERT_GT(0.03, 0.5 * h);  // the web is a sheet of one or two voxels
  ASSERT_LT(0.03, 1.0 * h);
  EXPECT_EQ(measure_shape(band).genus, 0.0);
  ASSERT_TRUE(inside_at(band, {0, 0, 0}));
  const std::vector<Vec3d> points = torus_points();
  const PointIndex index(points);
  const WebTunnels r = open_web_tunnels(std::move(band), index, settings(h), {});
  EXPECT_EQ(r.tunnels, 1);
  EXPECT_GT(r.voxels, 100u);
  EXPECT_FALSE(r.bricks.empty());
  EXPECT_FALSE(inside_at(r.band, {0, 0, 0}));
  const ShapeMeasures m = measure_shape(r.band);
  EXPECT_TRUE(m.watertight);
  EXPECT_EQ(m.components, 1u);
  EXPECT_EQ(m.genus, 1.0);
  // The torus itself is where it was: its points lie on the new zero level.
  BandAccessor acc(r.band);
  double worst = 0.0;
  for (std::size_t i = 0; i < points.size(); i += 37) {
    const Vec3d q = r.band.to_index_space(points[i]);
    const std::optional<float> u = acc.probe(Coord{int(std::lround(q.x)), int(std::lround(q.y)), int(std::lround(q.z))});
    ASSERT_TRUE(u.has_value());
    worst = std::max(worst, std::abs(double(*u)));
  }
  EXPECT_LT(worst, 1.0 * h);
}

TEST(WebTunnels, ASheetThePointsSampleStays) {
  // The same web, now sampled (points on both of its faces): nothing lies clear of them.
  NarrowBand band = webbed_torus(0.03);
  const double h = band.voxel_size();
  std::vector<Vec3d> points = torus_points();
  for (double x = -0.7; x <= 0.7; x += 0.015)
    for (double y = -0.7; y <= 0.7; y += 0.015)
      if (x * x + y * y < 0.7 * 0.7) {
        points.push_back({x, y, 0.03});
        points.push_back({x, y, -0.03});
      }
  const PointIndex index(points);
  const WebTunnels r = open_web_tunnels(std::move(band), index, settings(h), {});
  EXPECT_EQ(r.tunnels, 0);
  EXPECT_TRUE(inside_at(r.band, {0, 0, 0}));
  EXPECT_EQ(measure_shape(r.band).genus, 0.0);
}

TEST(WebTunnels, APartsInteriorBesideAHoleInTheSamplingStays) {
  // The plain torus (no web) sampled everywhere but a patch of its outer side, wider than the
  // clearance: the inside voxels under the patch are clear of every point, but they are the
  // torus's interior (a slab along the band's inner edge, little of it beside the outside),
  // and removing them would open no tunnel.
  NarrowBand band = webbed_torus(-1.0);  // a disk of negative thickness: no web
  const double h = band.voxel_size();
  EXPECT_EQ(measure_shape(band).genus, 1.0);
  std::vector<Vec3d> points;
  for (const Vec3d& p : torus_points())
    if (!(p.x > 1.0 && std::abs(p.y) < 0.3)) points.push_back(p);
  const PointIndex index(points);
  const WebTunnels r = open_web_tunnels(std::move(band), index, settings(h), {});
  EXPECT_EQ(r.tunnels, 0);
  EXPECT_TRUE(inside_at(r.band, {kMajor + 0.2, 0, 0}));
  EXPECT_EQ(measure_shape(r.band).genus, 1.0);
}

// A square plate |x|, |y| <= 1, |z| <= 1.5 h (three voxel layers at resolution 64 of its box)
// as the start shell leaves it: whole, any hole in it filled.
constexpr double kPlateVoxels = 64;
constexpr double kHole = 3.5;  // the hole's radius, voxels
NarrowBand filled_plate(double& h) {
  BBox box;
  box.extend({-1, -1, -0.2});
  box.extend({1, 1, 0.2});
  SdfBuildOptions options;
  options.frame = frame_for_resolution(box, int(kPlateVoxels), 3.0);
  h = options.frame.voxel_size;
  const double t = 1.5 * h;
  auto sdf = [t](const Vec3d& p) { return std::max({std::abs(p.x) - 1.0, std::abs(p.y) - 1.0, std::abs(p.z) - t}); };
  return build_from_sdf(sdf, box, options).band;
}

// Points on the plate's two faces, spacing h / 3, except within `hole` of the z axis; with
// `wall`, also on the cylinder of that radius between the faces (a hole through the plate).
std::vector<Vec3d> plate_points(double h, double hole, bool wall) {
  std::vector<Vec3d> p;
  const double t = 1.5 * h, step = h / 3.0;
  for (double x = -0.5; x <= 0.5; x += step)
    for (double y = -0.5; y <= 0.5; y += step)
      if (std::hypot(x, y) >= hole) {
        p.push_back({x, y, t});
        p.push_back({x, y, -t});
      }
  if (wall)
    for (double z = -t; z <= t; z += step)
      for (int k = 0; k < 64; ++k) {
        const double a = 2 * std::numbers::pi * k / 64;
        p.push_back({hole * std::cos(a), hole * std::sin(a), z});
      }
  return p;
}

// The plate's settings: a clearance whose fine pass's (2 h) exceeds the plate's half-thickness,
// so that only the hole's core is clear of the points.
WebTunnelSettings fine_settings(double h) {
  WebTunnelSettings s = settings(h);
  s.clearance = 4.0 * h;
  s.fine_clearance = kFineTunnelClearance * s.clearance;
  s.shallow_depth = kShallowLiningVoxels * h;
  return s;
}

TEST(WebTunnels, TheFinePassOpensAHoleNarrowerThanTheClearanceThroughAThinPlate) {
  double h = 0;
  NarrowBand band = filled_plate(h);
  EXPECT_EQ(measure_shape(band).genus, 0.0);
  const PointIndex index(plate_points(h, kHole * h, true));
  // The wide pass alone: the hole's core is within the clearance of its wall.
  WebTunnelSettings wide_only = fine_settings(h);
  wide_only.fine_clearance = 0.0;
  const WebTunnels wide = open_web_tunnels(band, index, wide_only, {});
  EXPECT_EQ(wide.tunnels, 0);
  EXPECT_EQ(measure_shape(wide.band).genus, 0.0);
  const WebTunnels r = open_web_tunnels(std::move(band), index, fine_settings(h), {});
  EXPECT_EQ(r.tunnels, 1);
  EXPECT_FALSE(inside_at(r.band, {0, 0, 0}));
  EXPECT_TRUE(inside_at(r.band, {0.3, 0.3, 0}));
  const ShapeMeasures m = measure_shape(r.band);
  EXPECT_TRUE(m.watertight);
  EXPECT_EQ(m.components, 1u);
  EXPECT_EQ(m.genus, 1.0);
}

TEST(WebTunnels, TheFinePassLeavesAPlateWhoseSamplingHasAHole) {
  // The same plate whole, its points missing on both faces within kHole h of the axis and no
  // wall: the voxels there are as clear, but the points around them lie on the surface.
  double h = 0;
  NarrowBand band = filled_plate(h);
  const PointIndex index(plate_points(h, kHole * h, false));
  const WebTunnels r = open_web_tunnels(std::move(band), index, fine_settings(h), {});
  EXPECT_EQ(r.tunnels, 0);
  EXPECT_TRUE(inside_at(r.band, {0, 0, 0}));
  EXPECT_EQ(measure_shape(r.band).genus, 0.0);
}

}  // namespace
}  // namespace levelset::apps::detail
