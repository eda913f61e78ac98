#include <gtest/gtest.h>

#include "core/error.hpp"
#include "render/image_codec.hpp"

using namespace levelset;
using namespace levelset::render;

namespace {
Image gradient(int w, int h) {
  Image img{w, h, std::vector<unsigned char>(std::size_t(w) * h * 3)};
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      unsigned char* p = img.rgb.data() + 3 * (std::size_t(y) * w + x);
      p[0] = (unsigned char)(x * 255 / (w - 1)), p[1] = (unsigned char)(y * 255 / (h - 1)), p[2] = 128;
    }
  return img;
}
}  // namespace

TEST(ImageCodec, PngRoundTripIsExact) {
  const Image img = gradient(123, 45);
  const std::string png = encode_png(img);
  EXPECT_EQ(png.substr(1, 3), "PNG");
  const Image back = decode_png(png);
  EXPECT_EQ(back.width, 123);
  EXPECT_EQ(back.height, 45);
  EXPECT_EQ(back.rgb, img.rgb);
}

TEST(ImageCodec, JpegRoundTripIsClose) {
  const Image img = gradient(200, 100);
  const std::string jpeg = encode_jpeg(img, 90);
  const Image back = decode_jpeg(jpeg);
  ASSERT_EQ(back.width, 200);
  ASSERT_EQ(back.height, 100);
  double diff = 0;
  for (std::size_t i = 0; i < img.rgb.size(); ++i) diff += std::abs(int(img.rgb[i]) - int(back.rgb[i]));
  EXPECT_LT(diff / double(img.rgb.size()), 3.0);
}

TEST(ImageCodec, Errors) {
  Image bad{10, 10, std::vector<unsigned char>(10)};
  EXPECT_THROW(encode_png(bad), Error);
  EXPECT_THROW(encode_jpeg(gradient(16, 16), 0), Error);
  EXPECT_THROW(decode_png("not a png"), Error);
  EXPECT_THROW(decode_jpeg("not a jpeg"), Error);
}
