#include "render/egl_context.hpp"

#include <epoxy/gl.h>
#include <fmt/format.h>

#include <cstring>

#include "render/render_error.hpp"

// Under LeakSanitizer, what Mesa allocates while a display is set up and torn down is not
// checked: its driver keeps that state in its own globals and is unloaded by eglTerminate, after
// which LSan sees the memory as leaked (with a stack it cannot name, so no suppression can match).
#if defined(__has_feature)
#if __has_feature(address_sanitizer)
#define GVIO_LSAN 1
#endif
#elif defined(__SANITIZE_ADDRESS__)
#define GVIO_LSAN 1
#endif
#ifdef GVIO_LSAN
#include <sanitizer/lsan_interface.h>
#endif

namespace gvio::render {
namespace {

// Leak checking off for the calling thread while it lives (a no-op without sanitizers).
struct DriverAllocations {
#ifdef GVIO_LSAN
  DriverAllocations() {
    __lsan_disable();
  }
  ~DriverAllocations() {
    __lsan_enable();
  }
#else
  DriverAllocations() = default;
#endif
  DriverAllocations(const DriverAllocations&) = delete;
  DriverAllocations& operator=(const DriverAllocations&) = delete;
};

bool hasClientExtension(const char* name) {
  const char* ext = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
  return ext != nullptr && std::strstr(ext, name) != nullptr;
}

std::string glString(GLenum name) {
  const auto* s = reinterpret_cast<const char*>(glGetString(name));
  return s != nullptr ? s : "";
}

}  // namespace

EglContext::EglContext() {
  if (hasClientExtension("EGL_EXT_platform_device")) {
    auto query =
        reinterpret_cast<PFNEGLQUERYDEVICESEXTPROC>(eglGetProcAddress("eglQueryDevicesEXT"));
    EGLDeviceEXT devices[16];
    EGLint count = 0;
    if (query != nullptr && query(16, devices, &count)) {
      for (EGLint i = 0; i < count; ++i) {
        const EGLDisplay d = eglGetPlatformDisplayEXT(EGL_PLATFORM_DEVICE_EXT, devices[i], nullptr);
        if (tryDisplay(d, fmt::format("device {}", i))) return;
      }
    } else {
      info_.attempts.push_back("device: eglQueryDevicesEXT failed");
    }
  } else {
    info_.attempts.push_back("device: EGL_EXT_platform_device not offered");
  }
  if (hasClientExtension("EGL_MESA_platform_surfaceless")) {
    const EGLDisplay d =
        eglGetPlatformDisplayEXT(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
    if (tryDisplay(d, "surfaceless")) return;
  } else {
    info_.attempts.push_back("surfaceless: EGL_MESA_platform_surfaceless not offered");
  }
  if (tryDisplay(eglGetDisplay(EGL_DEFAULT_DISPLAY), "default")) return;
  std::string why;
  for (const auto& a : info_.attempts) why += (why.empty() ? "" : "; ") + a;
  throw RenderError("no headless OpenGL 3.3 context through EGL (" + why +
                    "); install libegl-mesa0 and libgl1-mesa-dri, or an NVIDIA driver with EGL");
}

bool EglContext::tryDisplay(EGLDisplay display, const std::string& platform) {
  [[maybe_unused]] const DriverAllocations mesa;
  auto fail = [&](const char* step) {
    info_.attempts.push_back(
        fmt::format("{}: {} (EGL error 0x{:x})", platform, step, eglGetError()));
    if (display != EGL_NO_DISPLAY) eglTerminate(display);
    return false;
  };
  if (display == EGL_NO_DISPLAY) return fail("no display");
  EGLint major = 0, minor = 0;
  if (!eglInitialize(display, &major, &minor)) return fail("eglInitialize failed");
  if (!eglBindAPI(EGL_OPENGL_API)) return fail("no desktop OpenGL API");
  // No surface at all: everything renders into framebuffer objects. A config is still chosen
  // when available because some drivers reject EGL_NO_CONFIG_KHR.
  const EGLint config_attribs[] = {EGL_SURFACE_TYPE, EGL_PBUFFER_BIT, EGL_RENDERABLE_TYPE,
                                   EGL_OPENGL_BIT, EGL_NONE};
  EGLConfig config = nullptr;
  EGLint configs = 0;
  eglChooseConfig(display, config_attribs, &config, 1, &configs);
  const EGLint context_attribs[] = {EGL_CONTEXT_MAJOR_VERSION,
                                    3,
                                    EGL_CONTEXT_MINOR_VERSION,
                                    3,
                                    EGL_CONTEXT_OPENGL_PROFILE_MASK,
                                    EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT,
                                    EGL_NONE};
  const EGLContext context = eglCreateContext(display, configs > 0 ? config : EGL_NO_CONFIG_KHR,
                                              EGL_NO_CONTEXT, context_attribs);
  if (context == EGL_NO_CONTEXT) return fail("no OpenGL 3.3 core context");
  if (!eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, context)) {
    eglDestroyContext(display, context);
    return fail("eglMakeCurrent without a surface failed");
  }
  display_ = display;
  context_ = context;
  info_.platform = platform;
  info_.gl_version = glString(GL_VERSION);
  info_.gl_renderer = glString(GL_RENDERER);
  info_.gl_vendor = glString(GL_VENDOR);
  glGetIntegerv(GL_MAX_SAMPLES, &info_.max_samples);
  glGetIntegerv(GL_MAX_RENDERBUFFER_SIZE, &info_.max_renderbuffer_size);
  return true;
}

EglContext::~EglContext() {
  if (display_ == EGL_NO_DISPLAY) return;
  [[maybe_unused]] const DriverAllocations mesa;
  eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
  eglDestroyContext(display_, context_);
  eglTerminate(display_);
}

void EglContext::makeCurrent() const {
  if (!eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, context_)) {
    throw RenderError(fmt::format("eglMakeCurrent failed (EGL error 0x{:x})", eglGetError()));
  }
}

}  // namespace gvio::render
