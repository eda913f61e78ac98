// RGB8 images (top row first) as JPEG (libturbojpeg) or PNG (libpng, zlib level 1: ~10 ms for
// a 1024x768 frame, where stb took 55-65 ms). Errors: Error{InvalidArgument | IoError}.
#pragma once

#include <string>
#include <vector>

namespace levelset::render {

struct Image {
  int width = 0, height = 0;
  std::vector<unsigned char> rgb;  // width * height * 3, top row first
};

std::string encode_jpeg(const Image& image, int quality);
std::string encode_png(const Image& image);

}  // namespace levelset::render
