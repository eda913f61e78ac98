// Offscreen OpenGL 3.3 core contexts with no display, and the GL function table loaded from
// them (every gl* call goes through gl(); see gl_functions.hpp).
// - ContextKind::Egl: the EGL device platform on a hardware device (EGL_EXT_device_drm) when
//   one is present, else EGL surfaceless (EGL_PLATFORM_SURFACELESS_MESA: Mesa llvmpipe here).
//   No display, no environment variables.
// - ContextKind::OsMesa: OSMesaCreateContextAttribs with the core profile (the fallback; upstream
//   Mesa removed OSMesa in 25.1).
// Neither has a default framebuffer to speak of: draw into a Framebuffer (framebuffer.hpp);
// SceneRenderer::render does.
// Threading: the context is made current on the creating thread; a context is current on one
// thread at a time: create and use it on one thread (the daemon's render thread), or call
// make_current() on the thread that takes it over. Never fork() after one exists.
// Errors: Error{IoError} naming the call that failed ("eglInitialize",
// "OSMesaCreateContextAttribs", ...); Error{UnsupportedFormat} for a missing GL function.
// Cost: 10-50 ms to create (driver start-up).
#pragma once

#include <memory>
#include <string>

#include "render/gl_functions.hpp"

namespace levelset::render {

enum class ContextKind { Egl, OsMesa };

class OffscreenContext {
 public:
  virtual ~OffscreenContext() = default;
  virtual void make_current() = 0;
  const GlFunctions& gl() const { return gl_; }
  // "egl device" / "egl surfaceless" / "osmesa".
  virtual std::string platform() const = 0;
  // GL_RENDERER (GL_VERSION), e.g. "llvmpipe (LLVM 15.0.6, 256 bits) (4.5 (Core Profile) Mesa 22.3.6)".
  std::string renderer_name() const;

 protected:
  GlFunctions gl_;
};

std::unique_ptr<OffscreenContext> create_offscreen_context(ContextKind kind);

}  // namespace levelset::render
