// Region tools on images (apps/image_regions.hpp): box downsampling, lattice seeds, the
// threshold component of seeds, Dice; against values computed by hand.
#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

#include "apps/image_regions.hpp"
#include "core/error.hpp"

namespace levelset::apps {

namespace {

ImageVolume image_of(std::int64_t n, float (*f)(std::int64_t, std::int64_t, std::int64_t)) {
  ImageVolume im;
  im.nx = im.ny = im.nz = n;
  im.spacing = {0.5, 0.5, 2.0};
  im.origin = {1, 2, 3};
  im.samples.resize(im.voxel_count());
  for (std::int64_t k = 0; k < n; ++k)
    for (std::int64_t j = 0; j < n; ++j)
      for (std::int64_t i = 0; i < n; ++i) im.samples[im.index(i, j, k)] = f(i, j, k);
  return im;
}

}  // namespace

TEST(ImageRegions, DownsampleAveragesBlocksAndMovesTheOrigin) {
  // A linear ramp: the block average is the ramp at the block's centre.
  const ImageVolume im = image_of(9, [](std::int64_t i, std::int64_t j, std::int64_t k) { return float(i + 10 * j + 100 * k); });
  const ImageVolume d = downsample_image(im, 2);
  ASSERT_EQ(d.nx, 4);  // the ninth sample is dropped
  EXPECT_EQ(d.spacing, (Vec3d{1.0, 1.0, 4.0}));
  EXPECT_EQ(d.origin, (Vec3d{1.25, 2.25, 4.0}));  // + half a source voxel per axis
  for (std::int64_t k = 0; k < 4; ++k)
    for (std::int64_t j = 0; j < 4; ++j)
      for (std::int64_t i = 0; i < 4; ++i)
        EXPECT_FLOAT_EQ(d.at(i, j, k), float((2 * i + 0.5) + 10 * (2 * j + 0.5) + 100 * (2 * k + 0.5)));
  EXPECT_THROW(downsample_image(im, 0), Error);
  EXPECT_THROW(downsample_image(im, 10), Error);
}

TEST(ImageRegions, ThresholdComponentFollowsTheSeedsAndDiceCounts) {
  // Two bright slabs x in [1,3] and x in [6,8], separated by dark x = 4, 5.
  const ImageVolume im = image_of(10, [](std::int64_t i, std::int64_t, std::int64_t) {
    return (i >= 1 && i <= 3) || (i >= 6 && i <= 8) ? 10.0f : 0.0f;
  });
  const std::vector<std::uint8_t> left = threshold_component(im, 5.0f, {im.index(2, 5, 5)});
  std::uint64_t count = 0;
  for (std::int64_t k = 0; k < 10; ++k)
    for (std::int64_t j = 0; j < 10; ++j)
      for (std::int64_t i = 0; i < 10; ++i) {
        const bool expect = i >= 1 && i <= 3;
        EXPECT_EQ(left[im.index(i, j, k)] != 0, expect) << i << " " << j << " " << k;
        count += left[im.index(i, j, k)];
      }
  EXPECT_EQ(count, 300u);
  // A dark seed starts nothing; both seeds give both slabs.
  const std::vector<std::uint8_t> none = threshold_component(im, 5.0f, {im.index(4, 5, 5)});
  for (const std::uint8_t v : none) EXPECT_EQ(v, 0);
  const std::vector<std::uint8_t> both = threshold_component(im, 5.0f, {im.index(2, 5, 5), im.index(7, 0, 0)});
  EXPECT_DOUBLE_EQ(dice(left, both), 2.0 * 300 / (300 + 600));
  EXPECT_DOUBLE_EQ(dice(left, left), 1.0);
  EXPECT_DOUBLE_EQ(dice(none, none), 1.0);
  EXPECT_THROW(dice(left, std::vector<std::uint8_t>(3)), Error);
}

TEST(ImageRegions, LatticeSeedsLieDeepInsideBrightRegions) {
  // A bright cube [2, 17]^3 in a 20^3 image: seeds need their 7^3 box inside it.
  const ImageVolume im = image_of(20, [](std::int64_t i, std::int64_t j, std::int64_t k) {
    return i >= 2 && i <= 17 && j >= 2 && j <= 17 && k >= 2 && k <= 17 ? 1.0f : 0.0f;
  });
  const std::vector<std::size_t> seeds = seed_voxels_above(im, 0.5f, 3, 3);
  ASSERT_FALSE(seeds.empty());
  for (const std::size_t v : seeds) {
    const std::int64_t i = std::int64_t(v) % 20, j = (std::int64_t(v) / 20) % 20, k = std::int64_t(v) / 400;
    EXPECT_TRUE(i >= 5 && i <= 14 && j >= 5 && j <= 14 && k >= 5 && k <= 14) << i << " " << j << " " << k;
    EXPECT_EQ(i % 3, 0);
    EXPECT_EQ(j % 3, 0);
  }
  // i, j in {6, 9, 12}, k in {5, ..., 14}: 3 x 3 x 10.
  EXPECT_EQ(seeds.size(), 90u);
}

}  // namespace levelset::apps
