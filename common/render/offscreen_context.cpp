#include "render/offscreen_context.hpp"

#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <GL/osmesa.h>
#include <dlfcn.h>

#include <cstring>
#include <string>
#include <vector>

#include "core/error.hpp"

namespace levelset::render {

namespace {

[[noreturn]] void fail(const std::string& where, const std::string& why) { throw Error(ErrorCode::IoError, where, why); }

// The first EGL device backed by hardware (a DRM device), or EGL_NO_DEVICE_EXT.
EGLDeviceEXT hardware_device() {
  auto query_devices = reinterpret_cast<PFNEGLQUERYDEVICESEXTPROC>(eglGetProcAddress("eglQueryDevicesEXT"));
  auto query_string = reinterpret_cast<PFNEGLQUERYDEVICESTRINGEXTPROC>(eglGetProcAddress("eglQueryDeviceStringEXT"));
  if (query_devices == nullptr || query_string == nullptr) return EGL_NO_DEVICE_EXT;
  EGLint count = 0;
  if (!query_devices(0, nullptr, &count) || count <= 0) return EGL_NO_DEVICE_EXT;
  std::vector<EGLDeviceEXT> devices(static_cast<std::size_t>(count));
  if (!query_devices(count, devices.data(), &count)) return EGL_NO_DEVICE_EXT;
  for (EGLint i = 0; i < count; ++i) {
    const char* extensions = query_string(devices[std::size_t(i)], EGL_EXTENSIONS);
    if (extensions != nullptr && std::strstr(extensions, "EGL_EXT_device_drm") != nullptr &&
        std::strstr(extensions, "EGL_MESA_device_software") == nullptr)
      return devices[std::size_t(i)];
  }
  return EGL_NO_DEVICE_EXT;
}

class EglContext : public OffscreenContext {
 public:
  EglContext() {
    if (EGLDeviceEXT device = hardware_device(); device != EGL_NO_DEVICE_EXT) {
      try {
        open(eglGetPlatformDisplay(EGL_PLATFORM_DEVICE_EXT, device, nullptr));
        platform_ = "egl device";
      } catch (const Error&) {
        close();
      }
    }
    if (context_ == EGL_NO_CONTEXT) {
      open(eglGetPlatformDisplay(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr));
      platform_ = "egl surfaceless";
    }
    gl_ = load_gl_functions([](const char* name) { return reinterpret_cast<void*>(eglGetProcAddress(name)); });
  }
  ~EglContext() override { close(); }
  void make_current() override {
    if (!eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, context_)) fail("eglMakeCurrent", "cannot make it current");
  }
  std::string platform() const override { return platform_; }

 private:
  void open(EGLDisplay display) {
    display_ = display;
    if (display_ == EGL_NO_DISPLAY) fail("eglGetPlatformDisplay", "no EGL display");
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
    make_current();
  }
  void close() {
    if (display_ == EGL_NO_DISPLAY) return;
    eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    if (context_ != EGL_NO_CONTEXT) eglDestroyContext(display_, context_);
    eglTerminate(display_);
    display_ = EGL_NO_DISPLAY;
    context_ = EGL_NO_CONTEXT;
  }

  EGLDisplay display_ = EGL_NO_DISPLAY;
  EGLContext context_ = EGL_NO_CONTEXT;
  std::string platform_;
};

// libOSMesa, loaded on first use. Linked into the program, it pulls in LLVM, whose relocations
// and static constructors cost every levelsetd process ~0.2 s at start (`levelsetd --version`
// 0.21 s, 3,700 page faults), frames or not.
struct OsMesaApi {
  decltype(&OSMesaCreateContextAttribs) create_context_attribs = nullptr;
  decltype(&OSMesaMakeCurrent) make_current = nullptr;
  decltype(&OSMesaDestroyContext) destroy_context = nullptr;
  decltype(&OSMesaGetProcAddress) get_proc_address = nullptr;
};

template <typename F>
void bind(void* library, const char* name, F& f) {
  f = reinterpret_cast<F>(dlsym(library, name));
  if (f == nullptr) fail("libOSMesa", std::string("no symbol ") + name);
}

// Loaded once (a failed load throws and is tried again by the next context); thread-safe.
const OsMesaApi& osmesa() {
  static const OsMesaApi api = [] {
    void* library = nullptr;
    for (const char* name : {"libOSMesa.so.8", "libOSMesa.so"})
      if ((library = dlopen(name, RTLD_NOW | RTLD_LOCAL)) != nullptr) break;
    if (library == nullptr) {
      const char* why = dlerror();
      fail("libOSMesa", std::string("cannot load it: ") + (why ? why : "not found"));
    }
    OsMesaApi a;
    bind(library, "OSMesaCreateContextAttribs", a.create_context_attribs);
    bind(library, "OSMesaMakeCurrent", a.make_current);
    bind(library, "OSMesaDestroyContext", a.destroy_context);
    bind(library, "OSMesaGetProcAddress", a.get_proc_address);
    return a;  // the library stays loaded for the process's life
  }();
  return api;
}

class OsMesaContext : public OffscreenContext {
 public:
  OsMesaContext() : api_(osmesa()) {
    const int attribs[] = {OSMESA_FORMAT, OSMESA_RGBA, OSMESA_DEPTH_BITS, 24, OSMESA_PROFILE, OSMESA_CORE_PROFILE,
                           OSMESA_CONTEXT_MAJOR_VERSION, 3, OSMESA_CONTEXT_MINOR_VERSION, 3, 0};
    context_ = api_.create_context_attribs(attribs, nullptr);
    if (context_ == nullptr) fail("OSMesaCreateContextAttribs", "no OpenGL 3.3 core context");
    make_current();
    gl_ = load_gl_functions([](const char* name) { return reinterpret_cast<void*>(osmesa().get_proc_address(name)); });
  }
  ~OsMesaContext() override { api_.destroy_context(context_); }
  // OSMesa needs a buffer to be current; drawing goes to a framebuffer object.
  void make_current() override {
    if (!api_.make_current(context_, buffer_, GL_UNSIGNED_BYTE, 1, 1)) fail("OSMesaMakeCurrent", "cannot make it current");
  }
  std::string platform() const override { return "osmesa"; }

 private:
  const OsMesaApi& api_;
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

std::unique_ptr<OffscreenContext> create_offscreen_context(ContextKind kind) {
  if (kind == ContextKind::Egl) return std::make_unique<EglContext>();
  return std::make_unique<OsMesaContext>();
}

}  // namespace levelset::render
