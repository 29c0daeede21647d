#pragma once
// An off-screen render target: a multisampled framebuffer (colour RGBA8 + 24-bit depth) that is
// resolved into a single-sample one for readback. Sizes 1..16384 px per side.
#include "render/gl_objects.hpp"
#include "render/image.hpp"

namespace gvio::render {

constexpr int kMaxImageSize = 16384;

class Framebuffer {
 public:
  // `samples` is an upper bound: it is lowered to the driver's limit and so that the multisampled
  // buffers stay within ~1 GiB (a 16384 x 16384 target renders without multisampling).
  // Throws RenderError for sizes outside 1..16384 or above the driver's renderbuffer limit.
  Framebuffer(int width, int height, int samples = 4);

  [[nodiscard]] int width() const { return width_; }
  [[nodiscard]] int height() const { return height_; }
  [[nodiscard]] int samples() const { return samples_; }

  void bind() const;  // binds the multisampled target and sets the viewport
  void clear(float r, float g, float b, float a) const;
  // Resolve and read back; rows top to bottom.
  [[nodiscard]] ImageRgba readColor();
  // Window-space depth in [0, 1] (1 = nothing drawn), rows top to bottom.
  [[nodiscard]] std::vector<float> readDepth();

 private:
  void resolve(GLbitfield mask);

  int width_, height_, samples_;
  GlFramebuffer msaa_fbo_, resolve_fbo_;
  GlRenderbuffer msaa_color_, msaa_depth_, resolve_color_, resolve_depth_;
};

}  // namespace gvio::render
