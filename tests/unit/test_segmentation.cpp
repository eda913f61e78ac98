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
// The lower max_z slices of the image downsampled by f (apps/image_regions.hpp).
ImageVolume downsample(const ImageVolume& im, int f, std::int64_t max_z) {
  ImageVolume out = downsample_image(im, f);
  out.nz = std::min(out.nz, max_z);
  out.samples.resize(out.voxel_count());
  return out;
}

// Acceptance (thesis 3.4 on real data): CGAL's liver.inr.gz is a label image (0 background, 127
// a neighbouring organ, 255 the liver). Downsampled 4x (box average: voxels of 2.5 x 2.5 x 5.3
// mm) and cropped to its lower 24 slices (half the liver, to keep the test short), the liver
// segmented from seeds must agree with the connected components of {I > 127.5} (midway between
// the liver's 255 and the background's 0, so the 127 organ is outside) that contain the seeds:
// Dice >= 0.95, one closed surface. Seeds: the centres of the voxels whose 7^3 neighbourhood
// lies above the threshold, every 6th along x and y and every 3rd along z (a user's clicks
// spread over the organ), radius 2.5 voxels.
TEST(Segmentation, LiverMatchesThresholdComponent) {
  const char* env = std::getenv("LEVELSET_CGAL_DATA");
  const fs::path file = (env != nullptr && *env != '\0' ? fs::path(env) : fs::path(LEVELSET_CGAL_DATA)) / "images/liver.inr.gz";
  if (!fs::exists(file)) GTEST_SKIP() << "CGAL sample data not found at " << file;
  const ImageVolume im = downsample(read_image(file).image, 4, 24);
  const float t = 127.5f;
  SegmentationOptions o;
  const std::vector<std::size_t> seed_voxels = seed_voxels_above(im, t, 6, 3);
  for (const std::size_t v : seed_voxels)
    o.seeds.push_back({im.world(std::int64_t(v) % im.nx, (std::int64_t(v) / im.nx) % im.ny, std::int64_t(v) / (im.nx * im.ny)),
                       2.5 * im.spacing.x});
  ASSERT_GE(seed_voxels.size(), 10u);
  const std::vector<std::uint8_t> reference = threshold_component(im, t, seed_voxels);
  o.label_mask = true;
  o.motion_tolerance = 0.05;
  const SegmentationResult r = segment_image(im, o);
  const double dice_value = dice(reference, r.label_mask);
  std::uint64_t ref = 0;
  for (const std::uint8_t v : reference) ref += v;
  EXPECT_GE(dice_value, 0.95) << "reference " << ref << " voxels, segmented " << r.inside_voxels << ", " << r.steps
                        << " steps, converged " << r.converged;
  EXPECT_TRUE(r.converged);
  EXPECT_TRUE(r.measures.watertight);
  EXPECT_EQ(r.measures.components, 1u);
  std::printf("liver: Dice %.4f, %zu seeds, %llu reference voxels, %llu segmented, %d steps, t = %.1f, %.2f s\n", dice_value,
              seed_voxels.size(), (unsigned long long)ref, (unsigned long long)r.inside_voxels, r.steps, r.time,
              r.seconds_total);
}

}  // namespace
}  // namespace levelset::apps
