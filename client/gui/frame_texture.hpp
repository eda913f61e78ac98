// FrameTexture: a remote frame (RGB8 image) as a GL texture ImGui can draw behind the panel,
// and read_window: the window's framebuffer read back (glReadPixels) for screenshots (K).
// The few functions levelset_render's table lacks are loaded from the window's context here.
#pragma once

#include <string>

#include "render/gl_functions.hpp"
#include "render/image_codec.hpp"

namespace levelset::gui {

class FrameTexture {
 public:
  FrameTexture(const render::GlFunctions& gl, render::ProcAddress proc);
  ~FrameTexture();
  void upload(const render::Image& image);
  unsigned id() const { return texture_; }
  int width() const { return width_; }
  int height() const { return height_; }

 private:
  const render::GlFunctions& gl_;
  PFNGLTEXIMAGE2DPROC tex_image_2d_ = nullptr;
  unsigned texture_ = 0;
  int width_ = 0, height_ = 0;
};

// The window's back buffer after drawing (before the swap), top row first.
render::Image read_window(const render::GlFunctions& gl, int width, int height);
// PNG (levelset_render's encoder) written atomically; throws Error{IoError} when it cannot.
void write_png(const render::Image& image, const std::string& path);

}  // namespace levelset::gui
