// Min/max flow (apps/minmax_flow.hpp, thesis 3.3): a noisy box and a noisy sphere reach a
// steady state; the small bumps go, the large shape (volume, edges, radius) stays, unlike
// under mean curvature flow, which keeps shrinking.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>

#include "apps/minmax_flow.hpp"
#include "evolve/evolution.hpp"
#include "core/error.hpp"
#include "geometry/analytic_shapes.hpp"
#include "noisy_shapes.hpp"
#include "surface/marching_cubes.hpp"

namespace levelset::apps {

namespace {

const Vec3d kCentre{0.013, -0.007, 0.011};

}  // namespace

// A clean box is convex at every scale: Avg_R(u) > u along its faces' rims, edges and
// corners, so only concave parts could move and there are none: the flow is steady at once,
// where mean curvature flow for the same time rounds the edges and loses volume.
TEST(MinMaxFlow, CleanBoxIsSteadyWhereMeanCurvatureFlowRoundsIt) {
  const auto box = make_box(kCentre, {0.5, 0.4, 0.3});
  const BBox room{kCentre - Vec3d{0.7, 0.7, 0.7}, kCentre + Vec3d{0.7, 0.7, 0.7}};
  SdfBuildOptions so;
  so.frame = frame_for_resolution(room, 40, 3.0);
  const NarrowBand band = build_from_sdf([&](const Vec3d& p) { return box->distance(p); }, box->bounds(), so).band;
  MinMaxOptions o;
  o.radius = 3;
  o.max_steps = 100;
  const MinMaxResult r = minmax_flow(band, o);
  evolve::EvolutionOptions mc;
  mc.speed = evolve::mean_curvature_flow();
  mc.time = std::max(r.time, 1e-4);
  mc.redistance_every = 10;
  const double v_mcf = measure_shape(evolve::evolve(band, mc).band).volume;
  std::printf("clean box: steady %d after %d steps (t %.5f), volume %.5f -> %.5f (mean curvature flow: %.5f)\n",
              int(r.steady), r.steps, r.time, r.before.volume, r.after.volume, v_mcf);
  EXPECT_TRUE(r.steady);
  EXPECT_LE(r.steps, 10);
  EXPECT_NEAR(r.after.volume / r.before.volume, 1.0, 0.002);
  EXPECT_LT(v_mcf, r.after.volume);
}

// Area-weighted mean of min(H, 0)^2 over the zero level: the dents' roughness.
double concave_roughness(const NarrowBand& band) {
  const TriangleMesh mesh = marching_cubes(band).mesh;
  std::vector<double> h = vertex_mean_curvatures(band, mesh);
  for (double& v : h) v = std::min(v, 0.0);
  const CurvatureStats s = weighted_curvature_stats(mesh, h);
  return s.variance + s.mean * s.mean;
}

// A sphere (r0 = 15 voxels) with bumps (RMS 0.5 voxel, wavelength 6 voxels): at scale R = 6
// the surface is convex (Avg_R(u) - u ~ h^2 R (R+1) / (3 r0) = 0.9 h outweighs the bumps'
// displacement), so the flow fills the dents and leaves the bumps' tips (thesis: "the motion
// halts as soon as the convex hull is obtained", here the hull at scale R): it reaches a
// steady state, the concave roughness mostly goes, and the volume can only grow, by at most
// the bumps' amplitude times the area - unlike mean curvature flow, which shrinks it.
TEST(MinMaxFlow, NoisySphereFillsItsDentsAndStops) {
  const double r0 = 0.5;
  const BBox room{kCentre - Vec3d{0.7, 0.7, 0.7}, kCentre + Vec3d{0.7, 0.7, 0.7}};
  const GridFrame frame = frame_for_resolution(room, 48, 3.0);
  const double h = frame.voxel_size;
  const test::Bumps bumps(8, 0.5 * h, 6 * h, 5);
  auto clean = [&](const Vec3d& p) { return length(p - kCentre) - r0; };
  const BBox bounds{kCentre - Vec3d{r0, r0, r0}, kCentre + Vec3d{r0, r0, r0}};
  const NarrowBand band = test::noisy_band(clean, bumps, bounds, frame);
  MinMaxOptions o;
  o.radius = 6;
  o.tolerance = 5e-4;
  o.update_every = 2;
  o.max_steps = 300;
  const MinMaxResult r = minmax_flow(band, o);
  const double c0 = concave_roughness(band), c1 = concave_roughness(r.band);
  std::printf("noisy sphere: steady %d after %d steps (t %.5f), volume %.5f -> %.5f, concave roughness %.3f -> %.3f, "
              "var(H) %.2f -> %.2f, fitted r %.4f -> %.4f\n",
              int(r.steady), r.steps, r.time, r.before.volume, r.after.volume, c0, c1, r.before.curvature.variance,
              r.after.curvature.variance, r.before.sphere.radius, r.after.sphere.radius);
  EXPECT_TRUE(r.steady);
  EXPECT_LT(c1, 0.4 * c0);
  EXPECT_GE(r.after.volume, 0.995 * r.before.volume);
  EXPECT_LE(r.after.volume - r.before.volume, 1.5 * 0.5 * h * r.before.area);
  EXPECT_LT(r.after.curvature.variance, r.before.curvature.variance);
  ASSERT_FALSE(r.history.empty());
  EXPECT_EQ(r.history.back().step, r.steps);
}

TEST(MinMaxFlow, BoxAverageMinusValueIsTheScaledCurvatureOnASphere) {
  // u = |p| - r: over the cube of half-size R voxels at a surface voxel on the x axis,
  // Avg(u) - u ~ (sum of the tangential variances) / (2 r) = h^2 R (R + 1) / (3 r) > 0
  // (convex); the switch sees the sign of the curvature at scale R.
  const double r = 0.7;
  SdfBuildOptions so;
  const BBox bounds{{-r, -r, -r}, {r, r, r}};
  so.frame = frame_for_resolution(BBox{{-1, -1, -1}, {1, 1, 1}}, 64, 5.0);
  const NarrowBand band = build_from_sdf([r](const Vec3d& p) { return length(p) - r; }, bounds, so).band;
  const double h = band.voxel_size();
  BandAccessor acc(band);
  const Coord c{int(std::lround((r - band.origin().x) / h)), int(std::lround(-band.origin().y / h)),
                int(std::lround(-band.origin().z / h))};
  const Vec3d p = band.world(c);
  for (int R : {1, 2, 3}) {
    const double got = box_average(acc, c, R) - acc.value(c);
    const double expected = h * h * R * (R + 1) / (3.0 * length(p));
    EXPECT_NEAR(got / expected, 1.0, 0.1) << "R = " << R;
  }
}

TEST(MinMaxFlow, RejectsBadOptions) {
  SdfBuildOptions so;
  const BBox room{{-1, -1, -1}, {1, 1, 1}};
  so.frame = frame_for_resolution(room, 24, 3.0);
  const NarrowBand band = build_from_sdf([](const Vec3d& p) { return length(p) - 0.7; }, room, so).band;
  MinMaxOptions bad_radius;
  bad_radius.radius = 0;
  EXPECT_THROW(minmax_flow(band, bad_radius), Error);
  MinMaxOptions bad_tol;
  bad_tol.tolerance = std::nan("");
  EXPECT_THROW(minmax_flow(band, bad_tol), Error);
  MinMaxOptions bad_chunk;
  bad_chunk.update_every = 0;
  EXPECT_THROW(minmax_flow(band, bad_chunk), Error);
}

}  // namespace levelset::apps
