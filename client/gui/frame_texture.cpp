#include "frame_texture.hpp"

#include <algorithm>

#include "core/error.hpp"
#include "core/file_io.hpp"

namespace levelset::gui {

FrameTexture::FrameTexture(const render::GlFunctions& gl, render::ProcAddress proc) : gl_(gl) {
  tex_image_2d_ = reinterpret_cast<PFNGLTEXIMAGE2DPROC>(proc("glTexImage2D"));
  if (tex_image_2d_ == nullptr) throw Error(ErrorCode::UnsupportedFormat, "OpenGL", "the context has no glTexImage2D");
}

FrameTexture::~FrameTexture() {
  if (texture_ != 0) gl_.DeleteTextures(1, &texture_);
}

void FrameTexture::upload(const render::Image& image) {
  if (texture_ == 0) {
    gl_.GenTextures(1, &texture_);
    gl_.BindTexture(GL_TEXTURE_2D, texture_);
    gl_.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    gl_.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    gl_.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    gl_.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  }
  gl_.BindTexture(GL_TEXTURE_2D, texture_);
  gl_.PixelStorei(GL_UNPACK_ALIGNMENT, 1);
  tex_image_2d_(GL_TEXTURE_2D, 0, GL_RGB8, image.width, image.height, 0, GL_RGB, GL_UNSIGNED_BYTE, image.rgb.data());
  width_ = image.width;
  height_ = image.height;
}

render::Image read_window(const render::GlFunctions& gl, int width, int height) {
  render::Image image{width, height, std::vector<unsigned char>(std::size_t(width) * height * 3)};
  std::vector<unsigned char> rows(image.rgb.size());
  gl.BindFramebuffer(GL_FRAMEBUFFER, 0);
  gl.PixelStorei(GL_PACK_ALIGNMENT, 1);
  gl.ReadPixels(0, 0, width, height, GL_RGB, GL_UNSIGNED_BYTE, rows.data());
  const std::size_t stride = std::size_t(width) * 3;
  for (int y = 0; y < height; ++y)  // GL's first row is the bottom one
    std::copy_n(rows.data() + std::size_t(height - 1 - y) * stride, stride, image.rgb.data() + std::size_t(y) * stride);
  return image;
}

void write_png(const render::Image& image, const std::string& path) {
  write_file_atomically(path, render::encode_png(image));
}

}  // namespace levelset::gui
