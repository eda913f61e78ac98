#include "render/image_codec.hpp"

#include <png.h>
#include <turbojpeg.h>

#include <string>

#include "core/error.hpp"

namespace levelset::render {

namespace {
void check_image(const Image& image) {
  if (image.width <= 0 || image.height <= 0 || image.rgb.size() != std::size_t(image.width) * image.height * 3)
    throw Error(ErrorCode::InvalidArgument, "image", "pixels do not match the size");
}
}  // namespace

std::string encode_jpeg(const Image& image, int quality) {
  check_image(image);
  if (quality < 1 || quality > 100)
    throw Error(ErrorCode::InvalidArgument, "jpeg quality", "expected 1 to 100, found " + std::to_string(quality));
  tjhandle tj = tjInitCompress();
  if (tj == nullptr) throw Error(ErrorCode::IoError, "jpeg", "cannot start the encoder");
  unsigned char* out = nullptr;
  unsigned long size = 0;
  const int rc = tjCompress2(tj, image.rgb.data(), image.width, 0, image.height, TJPF_RGB, &out, &size, TJSAMP_420,
                             quality, TJFLAG_FASTDCT);
  std::string bytes = rc == 0 ? std::string(reinterpret_cast<char*>(out), size) : std::string();
  tjFree(out);
  tjDestroy(tj);
  if (rc != 0) throw Error(ErrorCode::IoError, "jpeg", "the encoder failed");
  return bytes;
}

std::string encode_png(const Image& image) {
  check_image(image);
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  png_infop info = png ? png_create_info_struct(png) : nullptr;
  if (info == nullptr) throw Error(ErrorCode::IoError, "png", "cannot start the encoder");
  std::string bytes;
  if (setjmp(png_jmpbuf(png))) {
    png_destroy_write_struct(&png, &info);
    throw Error(ErrorCode::IoError, "png", "the encoder failed");
  }
  png_set_write_fn(
      png, &bytes,
      [](png_structp p, png_bytep data, png_size_t n) {
        static_cast<std::string*>(png_get_io_ptr(p))->append(reinterpret_cast<char*>(data), n);
      },
      nullptr);
  png_set_compression_level(png, 1);
  png_set_IHDR(png, info, image.width, image.height, 8, PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE,
               PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  png_write_info(png, info);
  for (int y = 0; y < image.height; ++y)
    png_write_row(png, const_cast<png_bytep>(image.rgb.data() + std::size_t(y) * image.width * 3));
  png_write_end(png, nullptr);
  png_destroy_write_struct(&png, &info);
  return bytes;
}

Image decode_jpeg(std::string_view bytes) {
  tjhandle tj = tjInitDecompress();
  if (tj == nullptr) throw Error(ErrorCode::IoError, "jpeg", "cannot start the decoder");
  Image image;
  int subsampling = 0, colorspace = 0;
  const auto* data = reinterpret_cast<const unsigned char*>(bytes.data());
  bool ok = tjDecompressHeader3(tj, data, bytes.size(), &image.width, &image.height, &subsampling, &colorspace) == 0 &&
            image.width > 0 && image.height > 0;
  if (ok) {
    image.rgb.resize(std::size_t(image.width) * image.height * 3);
    ok = tjDecompress2(tj, data, bytes.size(), image.rgb.data(), image.width, 0, image.height, TJPF_RGB, 0) == 0;
  }
  tjDestroy(tj);
  if (!ok) throw Error(ErrorCode::ParseError, "jpeg", "the bytes do not decode as JPEG");
  return image;
}

Image decode_png(std::string_view bytes) {
  png_image png{};
  png.version = PNG_IMAGE_VERSION;
  if (!png_image_begin_read_from_memory(&png, bytes.data(), bytes.size()))
    throw Error(ErrorCode::ParseError, "png", "the bytes do not decode as PNG");
  png.format = PNG_FORMAT_RGB;
  Image image{int(png.width), int(png.height), std::vector<unsigned char>(PNG_IMAGE_SIZE(png))};
  if (!png_image_finish_read(&png, nullptr, image.rgb.data(), 0, nullptr)) {
    png_image_free(&png);
    throw Error(ErrorCode::ParseError, "png", "the bytes do not decode as PNG");
  }
  return image;
}

}  // namespace levelset::render
