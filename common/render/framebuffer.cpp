#include "render/framebuffer.hpp"

#include <cstring>
#include <string>

#include "core/error.hpp"

namespace levelset::render {

Framebuffer::~Framebuffer() {
  if (fbo_ == 0) return;
  gl_.DeleteFramebuffers(1, &fbo_);
  gl_.DeleteRenderbuffers(1, &color_);
  gl_.DeleteRenderbuffers(1, &depth_);
}

void Framebuffer::bind(int width, int height) {
  if (fbo_ == 0) {
    gl_.GenFramebuffers(1, &fbo_);
    gl_.GenRenderbuffers(1, &color_);
    gl_.GenRenderbuffers(1, &depth_);
  }
  gl_.BindFramebuffer(GL_FRAMEBUFFER, fbo_);
  if (width != width_ || height != height_) {
    gl_.BindRenderbuffer(GL_RENDERBUFFER, color_);
    gl_.RenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, width, height);
    gl_.BindRenderbuffer(GL_RENDERBUFFER, depth_);
    gl_.RenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT24, width, height);
    gl_.FramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, color_);
    gl_.FramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, depth_);
    if (gl_.CheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
      throw Error(ErrorCode::IoError, "framebuffer",
                  "incomplete at " + std::to_string(width) + "x" + std::to_string(height));
    width_ = width;
    height_ = height;
  }
  gl_.Viewport(0, 0, width, height);
}

std::vector<unsigned char> Framebuffer::read_rgb() const {
  const std::size_t stride = std::size_t(width_) * 3;
  std::vector<unsigned char> rows(stride * height_), flipped(rows.size());
  gl_.PixelStorei(GL_PACK_ALIGNMENT, 1);
  gl_.ReadPixels(0, 0, width_, height_, GL_RGB, GL_UNSIGNED_BYTE, rows.data());
  for (int y = 0; y < height_; ++y)
    std::memcpy(flipped.data() + std::size_t(y) * stride, rows.data() + std::size_t(height_ - 1 - y) * stride, stride);
  return flipped;
}

}  // namespace levelset::render
