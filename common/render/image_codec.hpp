// Image (RGB8, top row first) and its encodings: JPEG with libturbojpeg (4:2:0, fast DCT;
// ~1.6 ms for 1024x768 at quality 85) and PNG with libpng at zlib level 1 (~10 ms for
// 1024x768, where stb took 55-65 ms); decoders for tests and tools.
// Errors: Error{InvalidArgument} for an image whose pixels do not match its size or a quality
// outside 1..100; Error{IoError} when a codec fails; Error{ParseError} for bytes that do not
// decode. Threading: pure functions (each call has its own codec state).
#pragma once

#include <string>
#include <string_view>
#include <vector>

namespace levelset::render {

struct Image {
  int width = 0, height = 0;
  std::vector<unsigned char> rgb;  // width * height * 3, top row first
};

std::string encode_jpeg(const Image& image, int quality);
std::string encode_png(const Image& image);
Image decode_jpeg(std::string_view bytes);
Image decode_png(std::string_view bytes);

}  // namespace levelset::render
