// Fairing (apps/fairing.hpp, thesis 3.1, 5.1.2): a sphere with smooth random bumps of about
// half a voxel gets rounder under the three flows, each keeping its promise on the volume;
// a CGAL mesh's curvature variance drops. Also the shape measures against a clean sphere.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <numbers>

#include "apps/fairing.hpp"
#include "apps/shape_measures.hpp"
#include "core/error.hpp"
#include "distance/closest_point_transform.hpp"
#include "io/mesh_reader.hpp"
#include "noisy_shapes.hpp"

namespace levelset::apps {

namespace {

namespace fs = std::filesystem;

const Vec3d kCentre{0.013, -0.007, 0.011};
constexpr double kR0 = 0.5;

struct NoisySphere {
  NarrowBand band;
  double h = 0;
};

// r0 = 0.5 at 48 voxels over [-0.7, 0.7]^3 (h ~ 0.033, r0 ~ 15 voxels); 8 waves of
// wavelength 8 h, RMS 0.5 h.
NoisySphere noisy_sphere() {
  const BBox room{kCentre - Vec3d{0.7, 0.7, 0.7}, kCentre + Vec3d{0.7, 0.7, 0.7}};
  const GridFrame frame = frame_for_resolution(room, 48, 3.0);
  const double h = frame.voxel_size;
  const test::Bumps bumps(8, 0.5 * h, 8 * h, 7);
  const BBox bounds{kCentre - Vec3d{kR0, kR0, kR0}, kCentre + Vec3d{kR0, kR0, kR0}};
  return {test::noisy_band([](const Vec3d& p) { return length(p - kCentre) - kR0; }, bumps, bounds, frame), h};
}

double volume_radius(double volume) { return std::cbrt(3.0 * volume / (4.0 * std::numbers::pi)); }

void print(const char* name, const FairingResult& r) {
  std::printf("%s: %d steps t %.5f; volume %.5f -> %.5f; sphere rms %.5f -> %.5f; var(H) %.4f -> %.4f; "
              "max|H| %.2f -> %.2f\n",
              name, r.steps, r.time, r.before.volume, r.after.volume, r.before.sphere.rms_deviation,
              r.after.sphere.rms_deviation, r.before.curvature.variance, r.after.curvature.variance,
              r.before.curvature.max_abs, r.after.curvature.max_abs);
}

}  // namespace

TEST(ShapeMeasures, CleanSphereFitsAndHasUniformCurvature) {
  const BBox room{kCentre - Vec3d{0.7, 0.7, 0.7}, kCentre + Vec3d{0.7, 0.7, 0.7}};
  SdfBuildOptions o;
  o.frame = frame_for_resolution(room, 48, 3.0);
  const NarrowBand band = build_from_sdf([](const Vec3d& p) { return length(p - kCentre) - kR0; }, room, o).band;
  const ShapeMeasures m = measure_shape(band);
  const double h = band.voxel_size();
  EXPECT_NEAR(m.sphere.radius, kR0, 0.05 * h);
  EXPECT_LT(length(m.sphere.center - kCentre), 0.05 * h);
  EXPECT_LT(m.sphere.rms_deviation, 0.05 * h);
  EXPECT_NEAR(m.curvature.mean, 2.0 / kR0, 0.02 * 2.0 / kR0);
  EXPECT_LT(std::sqrt(m.curvature.variance), 0.03 * 2.0 / kR0);
  EXPECT_EQ(m.components, 1u);
  EXPECT_NEAR(m.genus, 0.0, 1e-9);
}

TEST(Fairing, VolumePreservingFlowRoundsANoisySphereKeepingItsVolume) {
  const NoisySphere s = noisy_sphere();
  FairingOptions o;
  o.flow = FairingFlow::VolumePreserving;
  // The bumps' wave number k = 2 pi / (8 h) decays like exp(-k^2 t): t = 3 / k^2 is ~95%.
  const double k = 2 * std::numbers::pi / (8 * s.h);
  o.time = 3.0 / (k * k);
  const FairingResult r = fair_surface(s.band, o);
  print("volume-preserving", r);
  EXPECT_NEAR(r.after.volume / r.before.volume, 1.0, 0.01);
  EXPECT_LT(r.after.sphere.rms_deviation, 0.4 * r.before.sphere.rms_deviation);
  EXPECT_LT(r.after.curvature.variance, 0.2 * r.before.curvature.variance);
}

TEST(Fairing, MeanCurvatureFlowRoundsAndShrinksAsRSquaredMinus4t) {
  const NoisySphere s = noisy_sphere();
  FairingOptions o;
  o.flow = FairingFlow::MeanCurvature;
  const double k = 2 * std::numbers::pi / (8 * s.h);
  o.time = 3.0 / (k * k);
  const FairingResult r = fair_surface(s.band, o);
  print("mean-curvature", r);
  const double expected = std::sqrt(volume_radius(r.before.volume) * volume_radius(r.before.volume) - 4 * r.time);
  EXPECT_NEAR(volume_radius(r.after.volume) / expected, 1.0, 0.01);
  EXPECT_LT(r.after.sphere.rms_deviation, 0.4 * r.before.sphere.rms_deviation);
  EXPECT_LT(r.after.curvature.variance, 0.2 * r.before.curvature.variance);
}

TEST(Fairing, MeanGaussianFlowRoundsAndShrinksAsRSquaredMinus2t) {
  const NoisySphere s = noisy_sphere();
  FairingOptions o;
  o.flow = FairingFlow::MeanGaussian;
  const double k = 2 * std::numbers::pi / (8 * s.h);
  o.time = 3.0 / (k * k);
  const FairingResult r = fair_surface(s.band, o);
  print("mean-gaussian", r);
  const double expected = std::sqrt(volume_radius(r.before.volume) * volume_radius(r.before.volume) - 2 * r.time);
  EXPECT_NEAR(volume_radius(r.after.volume) / expected, 1.0, 0.01);
  // The flow does not move saddle-shaped parts of the bumps (K < 0): it rounds less than the
  // other two in the same time.
  EXPECT_LT(r.after.sphere.rms_deviation, 0.6 * r.before.sphere.rms_deviation);
  EXPECT_LT(r.after.curvature.variance, 0.5 * r.before.curvature.variance);
}

TEST(Fairing, CgalMeshCurvatureVarianceDrops) {
  const char* env = std::getenv("LEVELSET_CGAL_DATA");
  const fs::path dir = (env != nullptr && *env != '\0' ? fs::path(env) : fs::path(LEVELSET_CGAL_DATA)) / "meshes";
  const fs::path file = dir / "elephant.off";
  ASSERT_TRUE(fs::exists(file)) << "CGAL data not installed: " << file
                                << " (install-deps.sh installs it)";
  const TriangleMesh mesh = read_mesh(file).mesh;
  CptOptions co;
  co.frame = frame_for_resolution(mesh.bounds(), 64, 3.0);
  const NarrowBand band = closest_point_transform(mesh, co).band;
  FairingOptions o;
  o.flow = FairingFlow::MeanCurvature;
  o.steps = 20;
  const FairingResult r = fair_surface(band, o);
  print("elephant R64 mean-curvature 20 steps", r);
  EXPECT_LT(r.after.curvature.variance, 0.7 * r.before.curvature.variance);
  // Mean curvature flow's promise: dV/dt = -(integral of H dA) = -(mean H) * area.
  const double rate0 = r.before.curvature.mean * r.before.area, rate1 = r.after.curvature.mean * r.after.area;
  const double predicted = -0.5 * (rate0 + rate1) * r.time, measured = r.after.volume - r.before.volume;
  std::printf("  volume change %.6f, predicted %.6f\n", measured, predicted);
  EXPECT_NEAR(measured / predicted, 1.0, 0.25);
}

TEST(Fairing, RejectsBadOptions) {
  const NoisySphere s = noisy_sphere();
  FairingOptions both;
  both.time = 0.1;
  both.steps = 3;
  EXPECT_THROW(fair_surface(s.band, both), Error);
  FairingOptions neither;
  EXPECT_THROW(fair_surface(s.band, neither), Error);
  FairingOptions nan;
  nan.time = std::nan("");
  EXPECT_THROW(fair_surface(s.band, nan), Error);
  EXPECT_THROW(fairing_flow_from_name("laplace"), Error);
}

}  // namespace levelset::apps
