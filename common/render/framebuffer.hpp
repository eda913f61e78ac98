// Framebuffer: an offscreen framebuffer object (RGBA8 colour + 24-bit depth) to draw frames
// into and read them back as RGB8, top row first. Reallocated when the size changes.
// Errors: Error{IoError, "framebuffer"} when incomplete. Cost: read_rgb O(pixels) (a copy and
// a row flip). Threading: the context's thread; delete it while that context is current.
#pragma once

#include <vector>

#include "render/gl_functions.hpp"

namespace levelset::render {

class Framebuffer {
 public:
  explicit Framebuffer(const GlFunctions& gl) : gl_(gl) {}
  ~Framebuffer();
  Framebuffer(const Framebuffer&) = delete;
  Framebuffer& operator=(const Framebuffer&) = delete;

  void bind(int width, int height);  // also sets the viewport
  std::vector<unsigned char> read_rgb() const;

 private:
  const GlFunctions& gl_;
  unsigned fbo_ = 0, color_ = 0, depth_ = 0;
  int width_ = 0, height_ = 0;
};

}  // namespace levelset::render
