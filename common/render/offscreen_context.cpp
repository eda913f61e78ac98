#include "render/offscreen_context.hpp"

#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <GL/osmesa.h>

#include <cstring>

#include "core/error.hpp"

namespace levelset::render {

namespace {

[[noreturn]] void fail(const std::string& where, const std::string& why) { throw Error(ErrorCode::IoError, where, why); }

class EglContext : public OffscreenContext {
 public:
  EglContext() {
    display_ = eglGetPlatformDisplay(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
    if (display_ == EGL_NO_DISPLAY) fail("eglGetPlatformDisplay", "no surfaceless EGL display");
    EGLint major = 0, minor = 0;
    if (!eglInitialize(display_, &major, &minor)) fail("eglInitialize", "cannot initialise EGL");
    if (!eglBindAPI(EGL_OPENGL_API)) fail("eglBindAPI", "no desktop OpenGL through EGL");
    const EGLint config_attribs[] = {EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_NONE};
    EGLConfig config = nullptr;
    EGLint count = 0;
    eglChooseConfig(display_, config_attribs, &config, 1, &count);
    const EGLint context_attribs[] = {EGL_CONTEXT_MAJOR_VERSION, 3, EGL_CONTEXT_MINOR_VERSION, 3,
                                      EGL_CONTEXT_OPENGL_PROFILE_MASK, EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT, EGL_NONE};
    context_ = eglCreateContext(display_, count > 0 ? config : EGL_NO_CONFIG_KHR, EGL_NO_CONTEXT, context_attribs);
    if (context_ == EGL_NO_CONTEXT) fail("eglCreateContext", "no OpenGL 3.3 core context");
    if (!eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, context_)) fail("eglMakeCurrent", "cannot make it current");
    gl_ = load_gl_functions([](const char* name) { return reinterpret_cast<void*>(eglGetProcAddress(name)); });
  }
  ~EglContext() override {
    eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    eglDestroyContext(display_, context_);
    eglTerminate(display_);
  }

 private:
  EGLDisplay display_ = EGL_NO_DISPLAY;
  EGLContext context_ = EGL_NO_CONTEXT;
};

class OsMesaContext : public OffscreenContext {
 public:
  OsMesaContext() {
    const int attribs[] = {OSMESA_FORMAT, OSMESA_RGBA, OSMESA_DEPTH_BITS, 24, OSMESA_PROFILE, OSMESA_CORE_PROFILE,
                           OSMESA_CONTEXT_MAJOR_VERSION, 3, OSMESA_CONTEXT_MINOR_VERSION, 3, 0};
    context_ = OSMesaCreateContextAttribs(attribs, nullptr);
    if (context_ == nullptr) fail("OSMesaCreateContextAttribs", "no OpenGL 3.3 core context");
    // OSMesa needs a buffer to be current; drawing goes to our framebuffer object.
    if (!OSMesaMakeCurrent(context_, buffer_, GL_UNSIGNED_BYTE, 1, 1)) fail("OSMesaMakeCurrent", "cannot make it current");
    gl_ = load_gl_functions([](const char* name) { return reinterpret_cast<void*>(OSMesaGetProcAddress(name)); });
  }
  ~OsMesaContext() override { OSMesaDestroyContext(context_); }

 private:
  OSMesaContext context_ = nullptr;
  unsigned char buffer_[16] = {};
};

}  // namespace

std::string OffscreenContext::renderer_name() const {
  auto text = [&](GLenum what) {
    const GLubyte* s = gl_.GetString(what);
    return s ? std::string(reinterpret_cast<const char*>(s)) : std::string("?");
  };
  return text(GL_RENDERER) + " (" + text(GL_VERSION) + ")";
}

void OffscreenContext::bind_framebuffer(int width, int height) {
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
      fail("framebuffer", "incomplete at " + std::to_string(width) + "x" + std::to_string(height));
    width_ = width;
    height_ = height;
  }
  gl_.Viewport(0, 0, width, height);
}

std::vector<unsigned char> OffscreenContext::read_rgb(int width, int height) const {
  std::vector<unsigned char> flipped(std::size_t(width) * height * 3), rows(flipped.size());
  gl_.PixelStorei(GL_PACK_ALIGNMENT, 1);
  gl_.ReadPixels(0, 0, width, height, GL_RGB, GL_UNSIGNED_BYTE, rows.data());
  const std::size_t stride = std::size_t(width) * 3;
  for (int y = 0; y < height; ++y)
    std::memcpy(flipped.data() + std::size_t(y) * stride, rows.data() + std::size_t(height - 1 - y) * stride, stride);
  return flipped;
}

std::unique_ptr<OffscreenContext> create_offscreen_context(ContextKind kind) {
  if (kind == ContextKind::Egl) return std::make_unique<EglContext>();
  return std::make_unique<OsMesaContext>();
}

}  // namespace levelset::render
