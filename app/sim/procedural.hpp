#pragma once
// The procedural world's painting surface: a float canvas that paints seamless (wrapping) grey
// textures. Randomness comes from sim/rng.hpp (the same output with every standard library).
#include <vector>

#include "render/scene.hpp"
#include "sim/rng.hpp"

namespace gvio::sim {

// A width x height float image in grey levels (0 black .. 255 white). Every paint operation wraps
// around the borders, so textures tile seamlessly with GL_REPEAT.
class Canvas {
 public:
  Canvas(int width, int height, float value);

  [[nodiscard]] int width() const { return width_; }
  [[nodiscard]] int height() const { return height_; }
  [[nodiscard]] float at(int x, int y) const { return data_[index(x, y)]; }
  float& at(int x, int y) { return data_[index(x, y)]; }

  void addWhiteNoise(Rng& rng, double sigma);
  // Smooth periodic value noise on a lattice of cells_x x cells_y cells, amplitude +-amplitude.
  void addValueNoise(Rng& rng, int cells_x, int cells_y, double amplitude);
  // Octaves of value noise from base_cells (per width) upwards, halving the amplitude each time.
  void addFractalNoise(Rng& rng, int base_cells, int octaves, double amplitude);
  // Anti-aliased axis-aligned rectangle [x0, x1) x [y0, y1) in pixels (fractional edges blend).
  void blendRect(double x0, double y0, double x1, double y1, double value, double alpha = 1.0);
  void addRect(double x0, double y0, double x1, double y1, double delta);
  // Disc with a soft edge of about one pixel; alpha < 1 mixes with what is there.
  void blendDisc(double cx, double cy, double radius, double value, double alpha = 1.0);
  // Thick segment (anti-aliased), e.g. cracks and joints.
  void blendLine(double x0, double y0, double x1, double y1, double width, double value,
                 double alpha = 1.0);
  void scale(double gain, double offset = 0.0);  // v -> gain * v + offset
  void clamp(double lo, double hi);

  [[nodiscard]] render::Texture toTexture() const;

 private:
  [[nodiscard]] std::size_t index(int x, int y) const;
  void blendPixel(int x, int y, double value, double weight);

  int width_, height_;
  std::vector<float> data_;
};

}  // namespace gvio::sim
