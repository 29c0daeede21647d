#pragma once
// A headless OpenGL 3.3+ core context through EGL, without any display server. Tried in order:
//   1. EGL_EXT_platform_device: each EGL device in turn (NVIDIA GPU servers, Mesa's devices),
//   2. EGL_MESA_platform_surfaceless (Mesa: llvmpipe on CPU-only machines and CI),
//   3. the default display.
// The first that yields a context wins; which one, and the GL renderer, are reported.
#include <epoxy/egl.h>

#include <string>
#include <vector>

namespace gvio::render {

struct ContextInfo {
  std::string platform;  // "device 0", "surfaceless", "default"
  std::string gl_version;
  std::string gl_renderer;
  std::string gl_vendor;
  int max_samples = 0;
  int max_renderbuffer_size = 0;
  std::vector<std::string> attempts;  // why earlier candidates failed
};

class EglContext {
 public:
  // Throws RenderError (see below) listing every attempt when no candidate works.
  EglContext();
  ~EglContext();
  EglContext(const EglContext&) = delete;
  EglContext& operator=(const EglContext&) = delete;

  [[nodiscard]] const ContextInfo& info() const { return info_; }
  void makeCurrent() const;

 private:
  bool tryDisplay(EGLDisplay display, const std::string& platform);

  EGLDisplay display_ = EGL_NO_DISPLAY;
  EGLContext context_ = EGL_NO_CONTEXT;
  ContextInfo info_;
};

}  // namespace gvio::render
