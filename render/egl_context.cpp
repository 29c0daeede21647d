#include "render/egl_context.hpp"

#include <epoxy/gl.h>
#include <fmt/format.h>

#include <cstring>

#include "render/render_error.hpp"

// Under the sanitizers Mesa's driver must stay loaded. LeakSanitizer: the driver keeps its
// per-process state (screens, shader caches, LLVM's JIT) in its own globals, and when eglTerminate
// unloads it those globals are unmapped, so LSan finds the memory they pointed to unreferenced and
// reports it as leaked (with stacks in a module that no longer exists); pinned, that memory is
// what it is: reachable. ThreadSanitizer: its suppressions name the driver
// (tests/sanitizers/tsan.supp), and it aborts when a library so named is unloaded.
#if defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer)
#define GVIO_PIN_DRIVER 1
#endif
#elif defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
#define GVIO_PIN_DRIVER 1
#endif
#ifdef GVIO_PIN_DRIVER
#include <dlfcn.h>
#include <link.h>
#endif

namespace gvio::render {
namespace {

// Keeps every loaded Mesa/LLVM driver module in memory for the rest of the process (RTLD_NOLOAD
// finds the module already loaded, RTLD_NODELETE pins it); a no-op without sanitizers.
void pinDriverModules() {
#ifdef GVIO_PIN_DRIVER
  dl_iterate_phdr(
      [](dl_phdr_info* info, std::size_t, void*) {
        const char* name = info->dlpi_name;
        if (name != nullptr && (std::strstr(name, "_dri.so") != nullptr ||
                                std::strstr(name, "libgallium") != nullptr ||
                                std::strstr(name, "libLLVM") != nullptr ||
                                std::strstr(name, "libEGL_mesa") != nullptr)) {
          dlopen(name, RTLD_NOW | RTLD_NOLOAD | RTLD_NODELETE);
        }
        return 0;
      },
      nullptr);
#endif
}

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
  auto fail = [&](const char* step) {
    info_.attempts.push_back(
        fmt::format("{}: {} (EGL error 0x{:x})", platform, step, eglGetError()));
    if (display != EGL_NO_DISPLAY) eglTerminate(display);
    return false;
  };
  if (display == EGL_NO_DISPLAY) return fail("no display");
  EGLint major = 0, minor = 0;
  const bool initialised = eglInitialize(display, &major, &minor) == EGL_TRUE;
  pinDriverModules();  // loaded by eglInitialize, even when it fails
  if (!initialised) return fail("eglInitialize failed");
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
