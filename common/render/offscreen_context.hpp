// Offscreen OpenGL 3.3 core contexts with no display: EGL surfaceless (Mesa llvmpipe here; the
// EGL device platform on a GPU) or OSMesa, and a framebuffer object of a requested size to draw
// into and read back. A context is current on the thread that made it; create and use it on
// one thread (the daemon's render thread).
// Errors: Error{IoError} naming what failed ("eglInitialize", "OSMesaCreateContextAttribs").
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "render/gl_functions.hpp"

namespace levelset::render {

enum class ContextKind { Egl, OsMesa };

class OffscreenContext {
 public:
  virtual ~OffscreenContext() = default;
  const GlFunctions& gl() const { return gl_; }
  std::string renderer_name() const;  // GL_VENDOR, GL_RENDERER, GL_VERSION
  // Binds a framebuffer of width x height (RGBA8 + depth), reallocated when the size changes.
  void bind_framebuffer(int width, int height);
  // The bound framebuffer as RGB8, top row first.
  std::vector<unsigned char> read_rgb(int width, int height) const;

 protected:
  GlFunctions gl_;

 private:
  unsigned fbo_ = 0, color_ = 0, depth_ = 0;
  int width_ = 0, height_ = 0;
};

std::unique_ptr<OffscreenContext> create_offscreen_context(ContextKind kind);

}  // namespace levelset::render
