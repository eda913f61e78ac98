// Long runs with default options stay healthy (issue 13): thousands of steps follow the
// analytic motion and the band stays within 1.5x of a fresh band around the same surface at
// every step, so memory stays flat; a surface that shrinks away ends the run cleanly.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>

#include "distance/redistance.hpp"
#include "evolve/evolution.hpp"
#include "geometry/analytic_shapes.hpp"
#include "grid/build_from_sdf.hpp"
#include "surface/marching_cubes.hpp"
#include "surface/mesh_measures.hpp"

namespace levelset::evolve {

namespace {

const Vec3d kCentre{0.013, -0.007, 0.011};

NarrowBand band_of(const SdfFunction& sdf, const BBox& bounds, int resolution) {
  SdfBuildOptions options;
  options.frame = frame_for_resolution(bounds, resolution, 3.0);
  return build_from_sdf(sdf, bounds, options).band;
}

NarrowBand sphere_band(const Vec3d& centre, double r, double room, int resolution) {
  const BBox box{centre - Vec3d{room, room, room}, centre + Vec3d{room, room, room}};
  return band_of([=](const Vec3d& p) { return length(p - centre) - r; }, box, resolution);
}

// Voxels of a fresh band of half-width W around a sphere of radius r: the shell's volume in
// voxels (the lattice count differs by well under 1 %).
double fresh_sphere_voxels(double r, double w, double h) {
  const double outer = r + w * h, inner = std::max(0.0, r - w * h);
  return 4.0 / 3.0 * std::numbers::pi * (outer * outer * outer - inner * inner * inner) / (h * h * h);
}

MeshMeasures surface_of(const NarrowBand& band) { return measure_mesh(marching_cubes(band).mesh); }

double volume_radius(const NarrowBand& band) {
  return std::cbrt(3.0 * surface_of(band).volume / (4.0 * std::numbers::pi));
}

// Records the largest ratio of active voxels to a fresh band's over a run.
struct GrowthWatch {
  double worst = 0;
  int worst_step = 0;
  void see(const StepInfo& s, double fresh) {
    const double ratio = double(s.active_voxels) / fresh;
    if (ratio > worst) {
      worst = ratio;
      worst_step = s.step;
    }
  }
};

// A fresh band around the surface the step left: the band redistanced with its own
// half-width (voxels with |d| > W h dropped; the domain is the band's own, so this can only
// undercount, which makes the bound stricter).
double fresh_voxels_of(const NarrowBand& band) { return double(redistance(band, {}).band.active_voxel_count()); }

}  // namespace

TEST(LongEvolution, MeanCurvatureFlowWithDefaultsShrinksASphereToHalfItsRadius) {
  const double r0 = 0.5, t_end = 3.0 * r0 * r0 / 16.0;  // r(t_end) = r0 / 2
  const NarrowBand band = sphere_band(kCentre, r0, 0.6, 88);
  const double h = band.voxel_size(), w = band.half_width();
  EvolutionOptions o;  // defaults, as the CLI and job files give them
  o.speed = mean_curvature_flow();
  o.time = t_end;
  GrowthWatch growth;
  double worst_radius_error = 0;
  int checks = 0;
  o.on_step = [&](const StepInfo& s) {
    const double expected = std::sqrt(r0 * r0 - 4.0 * s.time);
    growth.see(s, fresh_sphere_voxels(expected, w, h));
    if (s.step % 250 == 0) {
      const double radius = volume_radius(*s.band);
      worst_radius_error = std::max(worst_radius_error, std::abs(radius / expected - 1.0));
      ++checks;
    }
  };
  const EvolutionResult r = evolve(band, o);
  ASSERT_EQ(r.stop, StopReason::Completed) << r.message;
  const double radius = volume_radius(r.band), expected = r0 / 2;
  worst_radius_error = std::max(worst_radius_error, std::abs(radius / expected - 1.0));
  std::printf("%d steps, %d redistances (%d by growth), radius %.5f expected %.5f, worst radius error %.3f%% over "
              "%d checks, worst band %.3fx fresh at step %d\n",
              r.steps, r.redistance_count, r.growth_redistance_count, radius, expected, 100 * worst_radius_error,
              checks + 1, growth.worst, growth.worst_step);
  EXPECT_GT(r.steps, 2000);
  EXPECT_GT(checks, 8);
  EXPECT_LT(worst_radius_error, 0.01);
  EXPECT_LT(growth.worst, 1.5);
  EXPECT_GT(r.redistance_count, 0);  // the default drift tolerance acted
}

TEST(LongEvolution, Weno5Rk3TranslationForTwoThousandStepsKeepsTheBandBounded) {
  const double r0 = 0.3;
  const NarrowBand band = sphere_band(kCentre, r0, 0.45, 40);
  const double h = band.voxel_size(), w = band.half_width();
  EvolutionOptions o;
  o.velocity.kind = Velocity::Kind::Constant;
  o.velocity.constant = {1.0, -0.6, 0.35};  // not along a grid axis or diagonal
  o.scheme = Scheme::Weno5;
  o.rk_order = 3;
  o.steps = 2000;
  GrowthWatch growth;
  const double fresh = fresh_sphere_voxels(r0, w, h);
  o.on_step = [&](const StepInfo& s) { growth.see(s, fresh); };
  const EvolutionResult r = evolve(band, o);
  ASSERT_EQ(r.stop, StopReason::Completed) << r.message;
  const double travelled = length(o.velocity.constant) * r.time / h;
  const TriangleMesh mesh = marching_cubes(r.band).mesh;
  const MeshMeasures m = measure_mesh(mesh);
  const double radius = std::cbrt(3.0 * m.volume / (4.0 * std::numbers::pi));
  Vec3d centre{};
  for (const Vec3d& v : mesh.vertices) centre = centre + v * (1.0 / double(mesh.vertices.size()));
  const Vec3d expected_centre = kCentre + o.velocity.constant * r.time;
  std::printf("travelled %.0f voxels in %d steps, %d redistances (%d by growth, %d land mines), radius %.5f (r0 "
              "%.5f), centre off by %.3f voxels, worst band %.3fx fresh at step %d\n",
              travelled, r.steps, r.redistance_count, r.growth_redistance_count, r.landmine_count, radius, r0,
              length(centre - expected_centre) / h, growth.worst, growth.worst_step);
  EXPECT_GT(travelled, 500.0);
  EXPECT_LT(growth.worst, 1.5);
  EXPECT_LT(std::abs(radius - r0), h);  // 11 voxels of radius after > 1000 voxels of travel
  EXPECT_LT(length(centre - expected_centre), 0.5 * h);
  EXPECT_EQ(m.components, 1u);
}

// The knot's tube shrinks away under mean-curvature flow in 6 (a/h)^2 steps (a: tube radius;
// the parabolic step is h^2 / 12), so 2000 steps need a tube 18 voxels thick: a thick-tubed
// knot at a resolution that gives it that.
TEST(LongEvolution, KnotUnderMeanCurvatureForTwoThousandStepsKeepsTheBandBounded) {
  const auto knot = make_torus_knot({0, 0, 0}, 2, 3, 1.0, 0.35, 0.3);
  const int resolution = 200;
  const NarrowBand band = band_of([&](const Vec3d& p) { return knot->distance(p); }, knot->bounds(), resolution);
  std::printf("tube radius %.1f voxels, %zu active voxels\n", 0.3 / band.voxel_size(), band.active_voxel_count());
  EvolutionOptions o;
  o.speed = mean_curvature_flow();
  o.steps = 2000;
  GrowthWatch growth;
  double fresh = fresh_voxels_of(band);
  int measured = 0;
  o.on_step = [&](const StepInfo& s) {
    if (s.step % 10 == 0) {  // the surface moves about 0.1 voxel in 10 steps
      fresh = fresh_voxels_of(*s.band);
      ++measured;
    }
    growth.see(s, fresh);
  };
  const EvolutionResult r = evolve(band, o);
  ASSERT_EQ(r.stop, StopReason::Completed) << r.message;
  const MeshMeasures m = surface_of(r.band);
  std::printf("%d steps, %d redistances (%d by growth), %zu -> %zu active voxels, worst band %.3fx fresh at step %d "
              "(%d fresh bands), genus %g\n",
              r.steps, r.redistance_count, r.growth_redistance_count, band.active_voxel_count(),
              r.band.active_voxel_count(), growth.worst, growth.worst_step, measured, m.genus);
  EXPECT_EQ(r.steps, 2000);
  EXPECT_LT(growth.worst, 1.5);
  EXPECT_TRUE(m.watertight);
  EXPECT_LT(r.band.active_voxel_count(), band.active_voxel_count());  // a shrinking surface
}

TEST(LongEvolution, ASphereThatShrinksAwayStopsWithAnEmptyBand) {
  const double r0 = 0.5;
  const NarrowBand band = sphere_band(kCentre, r0, 0.6, 48);
  EvolutionOptions o;
  o.speed = mean_curvature_flow();
  o.steps = 5000;  // far past t = r0^2 / 4 where the sphere vanishes
  std::uint64_t most = 0;
  o.on_step = [&](const StepInfo& s) { most = std::max<std::uint64_t>(most, s.active_voxels); };
  const EvolutionResult r = evolve(band, o);
  EXPECT_EQ(r.stop, StopReason::Vanished);
  EXPECT_NE(r.message.find("vanished"), std::string::npos) << r.message;
  EXPECT_LT(r.steps, 5000);
  EXPECT_NEAR(r.time, r0 * r0 / 4.0, 0.05 * r0 * r0 / 4.0);
  EXPECT_EQ(r.band.active_voxel_count(), 0u);
  EXPECT_FALSE(r.band.far_inside());
  EXPECT_LE(most, band.active_voxel_count());
  // An input with no surface at all stops at once.
  const EvolutionResult again = evolve(r.band, o);
  EXPECT_EQ(again.stop, StopReason::Vanished);
  EXPECT_EQ(again.steps, 0);
}

}  // namespace levelset::evolve
