#include "render/framebuffer.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cstring>

#include "render/render_error.hpp"

namespace gvio::render {
namespace {

GlRenderbuffer makeRenderbuffer(GLenum format, int width, int height, int samples) {
  GLuint id = 0;
  glGenRenderbuffers(1, &id);
  glBindRenderbuffer(GL_RENDERBUFFER, id);
  glRenderbufferStorageMultisample(GL_RENDERBUFFER, samples, format, width, height);
  return GlRenderbuffer(id);
}

GlFramebuffer makeFramebuffer(const GlRenderbuffer& color, const GlRenderbuffer& depth) {
  GLuint id = 0;
  glGenFramebuffers(1, &id);
  glBindFramebuffer(GL_FRAMEBUFFER, id);
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, color.get());
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, depth.get());
  const GLenum status = glCheckFramebufferStatus(GL_FRAMEBUFFER);
  GlFramebuffer fbo(id);
  if (status != GL_FRAMEBUFFER_COMPLETE) {
    throw RenderError(fmt::format("framebuffer incomplete (status 0x{:x})", status));
  }
  return fbo;
}

// Rows arrive bottom-up from glReadPixels; images are top-down.
template <typename T>
void flipRows(std::vector<T>& data, std::size_t row_elems, int height) {
  std::vector<T> tmp(row_elems);
  for (int y = 0; y < height / 2; ++y) {
    T* a = data.data() + static_cast<std::size_t>(y) * row_elems;
    T* b = data.data() + static_cast<std::size_t>(height - 1 - y) * row_elems;
    std::memcpy(tmp.data(), a, row_elems * sizeof(T));
    std::memcpy(a, b, row_elems * sizeof(T));
    std::memcpy(b, tmp.data(), row_elems * sizeof(T));
  }
}

}  // namespace

Framebuffer::Framebuffer(int width, int height, int samples) : width_(width), height_(height) {
  GLint max_rb = 0, max_samples = 0;
  glGetIntegerv(GL_MAX_RENDERBUFFER_SIZE, &max_rb);
  glGetIntegerv(GL_MAX_SAMPLES, &max_samples);
  if (width < 1 || height < 1 || width > kMaxImageSize || height > kMaxImageSize ||
      width > max_rb || height > max_rb) {
    throw RenderError(fmt::format("image size {}x{} outside 1..{} px per side (driver limit {})",
                                  width, height, kMaxImageSize, max_rb));
  }
  // 8 bytes per sample (RGBA8 + depth24/stencil8); keep the multisampled pair under 1 GiB.
  const double bytes_per_sample = 8.0 * width * height;
  const int memory_cap =
      std::max(1, static_cast<int>((1024.0 * 1024.0 * 1024.0) / bytes_per_sample));
  samples_ = std::clamp(std::min({samples, max_samples, memory_cap}), 1, 16);
  if (samples_ == 1) samples_ = 0;  // plain (non-multisampled) storage
  msaa_color_ = makeRenderbuffer(GL_RGBA8, width, height, samples_);
  msaa_depth_ = makeRenderbuffer(GL_DEPTH24_STENCIL8, width, height, samples_);
  msaa_fbo_ = makeFramebuffer(msaa_color_, msaa_depth_);
  resolve_color_ = makeRenderbuffer(GL_RGBA8, width, height, 0);
  resolve_depth_ = makeRenderbuffer(GL_DEPTH24_STENCIL8, width, height, 0);
  resolve_fbo_ = makeFramebuffer(resolve_color_, resolve_depth_);
  checkGl("Framebuffer");
}

void Framebuffer::bind() const {
  glBindFramebuffer(GL_FRAMEBUFFER, msaa_fbo_.get());
  glViewport(0, 0, width_, height_);
}

void Framebuffer::clear(float r, float g, float b, float a) const {
  bind();
  glClearColor(r, g, b, a);
  glClearDepth(1.0);
  glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
}

void Framebuffer::resolve(GLbitfield mask) {
  glBindFramebuffer(GL_READ_FRAMEBUFFER, msaa_fbo_.get());
  glBindFramebuffer(GL_DRAW_FRAMEBUFFER, resolve_fbo_.get());
  // Depth cannot be averaged: GL_NEAREST takes one sample per pixel.
  glBlitFramebuffer(0, 0, width_, height_, 0, 0, width_, height_, mask, GL_NEAREST);
  glBindFramebuffer(GL_READ_FRAMEBUFFER, resolve_fbo_.get());
}

ImageRgba Framebuffer::readColor() {
  resolve(GL_COLOR_BUFFER_BIT);
  ImageRgba image;
  image.width = width_;
  image.height = height_;
  image.rgba.resize(static_cast<std::size_t>(width_) * static_cast<std::size_t>(height_) * 4);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadPixels(0, 0, width_, height_, GL_RGBA, GL_UNSIGNED_BYTE, image.rgba.data());
  checkGl("readColor");
  flipRows(image.rgba, static_cast<std::size_t>(width_) * 4, height_);
  return image;
}

std::vector<float> Framebuffer::readDepth() {
  resolve(GL_DEPTH_BUFFER_BIT);
  std::vector<float> depth(static_cast<std::size_t>(width_) * static_cast<std::size_t>(height_));
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadPixels(0, 0, width_, height_, GL_DEPTH_COMPONENT, GL_FLOAT, depth.data());
  checkGl("readDepth");
  flipRows(depth, static_cast<std::size_t>(width_), height_);
  return depth;
}

}  // namespace gvio::render
