// segment_image (thesis 3.4): a noisy synthetic ball is found within a voxel; CGAL's liver image
// is segmented like the threshold component of its seed (Dice >= 0.95); option errors.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <random>
#include <vector>

#include "apps/edge_indicator.hpp"
#include "apps/gaussian_smooth.hpp"
#include "apps/image_regions.hpp"
#include "apps/segmentation.hpp"
#include "core/error.hpp"
#include "io/image_reader.hpp"

namespace levelset::apps {
namespace {

namespace fs = std::filesystem;

// A ball of radius R (world) at c, intensity 200 inside and 100 outside with a one-voxel
// partial-volume ramp, plus uniform noise of +-amplitude (fixed seed).
ImageVolume noisy_ball(int n, double spacing, Vec3d origin, Vec3d c, double R, double amplitude) {
  ImageVolume im;
  im.nx = im.ny = im.nz = n;
  im.spacing = {spacing, spacing, spacing};
  im.origin = origin;
  im.samples.resize(im.voxel_count());
  std::mt19937 rng(12345);
  std::uniform_real_distribution<double> noise(-amplitude, amplitude);
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        const double d = (length(im.world(i, j, k) - c) - R) / spacing;
        im.samples[im.index(i, j, k)] = float(100 + 100 * std::clamp(0.5 - d, 0.0, 1.0) + noise(rng));
      }
  return im;
}

TEST(GaussianSmooth, KeepsConstantsAndMeanAndSpreadsAnImpulse) {
  ImageVolume im;
  im.nx = im.ny = im.nz = 15;
  im.samples.assign(im.voxel_count(), 2.0f);
  for (float v : gaussian_smooth(im, 1.5).samples) EXPECT_NEAR(v, 2.0f, 1e-5f);
  im.samples.assign(im.voxel_count(), 0.0f);
  im.samples[im.index(7, 7, 7)] = 1.0f;
  const ImageVolume s = gaussian_smooth(im, 1.0);
  double total = 0, second = 0;
  for (int k = 0; k < 15; ++k)
    for (int j = 0; j < 15; ++j)
      for (int i = 0; i < 15; ++i) {
        total += s.at(i, j, k);
        second += s.at(i, j, k) * (i - 7) * (i - 7);
      }
  EXPECT_NEAR(total, 1.0, 1e-5);
  EXPECT_NEAR(second, 1.0, 0.01);  // variance sigma^2 along x
  EXPECT_THROW(gaussian_smooth(im, -1), Error);
}

TEST(EdgeIndicator, SmallOnEdgesOneInFlatRegions) {
  const ImageVolume im = noisy_ball(32, 1.0, {}, {16, 16, 16}, 8, 0.0);
  const EdgeIndicator e = edge_indicator(im);
  EXPECT_NEAR(e.sample({16, 16, 16}), 1.0, 1e-3);  // flat inside
  EXPECT_NEAR(e.sample({2, 2, 2}), 1.0, 1e-3);     // flat outside
  EXPECT_LT(e.sample({24, 16, 16}), 0.05);          // on the sphere
  EXPECT_EQ(e.sample({-5, 16, 16}), 0.0);           // outside the image
  // grad g points away from the edge: inward just inside the sphere.
  EXPECT_LT(e.sample_gradient({22, 16, 16}).x, 0.0);
  EXPECT_GT(e.sample_gradient({26, 16, 16}).x, 0.0);
}

TEST(Segmentation, NoisyBallWithinOneVoxel) {
  const double h = 0.5, R = 6;
  const Vec3d c{10, 10.2, 9.9};
  const ImageVolume im = noisy_ball(48, h, {-2, -2, -2}, c, R, 15);
  SegmentationOptions o;
  o.seeds = {{c + Vec3d{0.5, -0.3, 0.2}, 0.0}};
  o.seed_radius = 2;
  o.label_mask = true;
  o.motion_tolerance = 0.05;
  const SegmentationResult r = segment_image(im, o);
  EXPECT_TRUE(r.converged) << r.steps << " steps, t " << r.time << ", motion " << r.last_motion;
  EXPECT_TRUE(r.measures.watertight);
  EXPECT_EQ(r.measures.components, 1u);
  EXPECT_EQ(r.measures.genus, 0.0);
  double mean = 0, worst = 0;
  for (const Vec3d& v : r.surface.mesh.vertices) {
    const double e = length(v - c) - R;
    mean += e;
    worst = std::max(worst, std::abs(e));
  }
  mean /= double(r.surface.mesh.vertices.size());
  EXPECT_LT(worst, h) << "mean radius error " << mean;
  EXPECT_LT(std::abs(mean), 0.5 * h);
  // The inside voxels: between the balls one voxel smaller and one voxel larger.
  auto ball_voxels = [&](double radius) { return 4.0 / 3.0 * M_PI * std::pow(radius / h, 3); };
  EXPECT_GT(double(r.inside_voxels), ball_voxels(R - h));
  EXPECT_LT(double(r.inside_voxels), ball_voxels(R + h));
}

TEST(Segmentation, OptionErrors) {
  const ImageVolume im = noisy_ball(16, 1.0, {}, {8, 8, 8}, 4, 0.0);
  auto fails = [&](auto&& edit) {
    SegmentationOptions o;
    o.seeds = {{{8, 8, 8}, 2.0}};
    edit(o);
    try {
      segment_image(im, o);
    } catch (const Error& e) {
      return e.code() == ErrorCode::InvalidArgument;
    }
    return false;
  };
  EXPECT_TRUE(fails([](SegmentationOptions& o) { o.seeds.clear(); }));
  EXPECT_TRUE(fails([](SegmentationOptions& o) { o.seeds[0].center.x = NAN; }));
  EXPECT_TRUE(fails([](SegmentationOptions& o) { o.seeds[0].center.x = 40; }));
  EXPECT_TRUE(fails([](SegmentationOptions& o) { o.seeds[0].radius = 0.5; }));
  EXPECT_TRUE(fails([](SegmentationOptions& o) { o.steps = 3; o.time = 1; }));
  EXPECT_TRUE(fails([](SegmentationOptions& o) { o.edge.power = 3; }));
  EXPECT_TRUE(fails([](SegmentationOptions& o) { o.edge.contrast = 0; }));
  EXPECT_TRUE(fails([](SegmentationOptions& o) { o.attraction = -1; }));
  EXPECT_TRUE(fails([](SegmentationOptions& o) { o.half_width = 1; }));
  SegmentationOptions huge;
  huge.seeds = {{{8, 8, 8}, 2.0}};
  huge.voxel_size = 1e-4;
  EXPECT_THROW(segment_image(im, huge), Error);
}

// Block average of factor f (the block's centre becomes the voxel), keeping z slices < max_z.
// The acceptance on real data (CGAL's liver.inr.gz against its threshold component, Dice
// >= 0.95) runs through the real binary as the job configs/jobs/segment_liver.conf
// (tests/integration/check_job.py), on the whole liver.

}  // namespace
}  // namespace levelset::apps
