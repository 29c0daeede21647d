#include "sim/procedural.hpp"

#include <algorithm>
#include <cmath>

namespace gvio::sim {
namespace {

int wrap(int i, int n) {
  const int m = i % n;
  return m < 0 ? m + n : m;
}

double smoothstep(double t) {
  return t * t * (3.0 - 2.0 * t);
}

// Length of the overlap of the unit pixel [i, i + 1) with [a, b).
double coverage(int i, double a, double b) {
  return std::max(0.0, std::min(b, i + 1.0) - std::max(a, static_cast<double>(i)));
}

}  // namespace

Canvas::Canvas(int width, int height, float value)
    : width_(width),
      height_(height),
      data_(static_cast<std::size_t>(width) * static_cast<std::size_t>(height), value) {}

std::size_t Canvas::index(int x, int y) const {
  return static_cast<std::size_t>(wrap(y, height_)) * static_cast<std::size_t>(width_) +
         static_cast<std::size_t>(wrap(x, width_));
}

void Canvas::blendPixel(int x, int y, double value, double weight) {
  float& v = at(x, y);
  v = static_cast<float>(static_cast<double>(v) + weight * (value - static_cast<double>(v)));
}

void Canvas::addWhiteNoise(Rng& rng, double sigma) {
  for (auto& v : data_) v = static_cast<float>(static_cast<double>(v) + sigma * rng.normal());
}

void Canvas::addValueNoise(Rng& rng, int cells_x, int cells_y, double amplitude) {
  cells_x = std::clamp(cells_x, 1, width_);
  cells_y = std::clamp(cells_y, 1, height_);
  std::vector<double> lattice(static_cast<std::size_t>(cells_x) *
                              static_cast<std::size_t>(cells_y));
  for (auto& l : lattice) l = rng.uniform(-amplitude, amplitude);
  auto node = [&](int i, int j) {
    return lattice[static_cast<std::size_t>(wrap(j, cells_y)) * static_cast<std::size_t>(cells_x) +
                   static_cast<std::size_t>(wrap(i, cells_x))];
  };
  for (int y = 0; y < height_; ++y) {
    const double fy = (y + 0.5) * cells_y / height_;
    const int j = static_cast<int>(std::floor(fy));
    const double ty = smoothstep(fy - j);
    for (int x = 0; x < width_; ++x) {
      const double fx = (x + 0.5) * cells_x / width_;
      const int i = static_cast<int>(std::floor(fx));
      const double tx = smoothstep(fx - i);
      const double top = node(i, j) + tx * (node(i + 1, j) - node(i, j));
      const double bottom = node(i, j + 1) + tx * (node(i + 1, j + 1) - node(i, j + 1));
      float& v = data_[static_cast<std::size_t>(y) * static_cast<std::size_t>(width_) +
                       static_cast<std::size_t>(x)];
      v = static_cast<float>(static_cast<double>(v) + top + ty * (bottom - top));
    }
  }
}

void Canvas::addFractalNoise(Rng& rng, int base_cells, int octaves, double amplitude) {
  int cells = base_cells;
  for (int o = 0; o < octaves && cells <= width_; ++o) {
    addValueNoise(rng, cells, cells * height_ / width_, amplitude);
    cells *= 2;
    amplitude *= 0.5;
  }
}

void Canvas::blendRect(double x0, double y0, double x1, double y1, double value, double alpha) {
  for (int y = static_cast<int>(std::floor(y0)); y < static_cast<int>(std::ceil(y1)); ++y) {
    const double cy = coverage(y, y0, y1);
    for (int x = static_cast<int>(std::floor(x0)); x < static_cast<int>(std::ceil(x1)); ++x)
      blendPixel(x, y, value, alpha * cy * coverage(x, x0, x1));
  }
}

void Canvas::addRect(double x0, double y0, double x1, double y1, double delta) {
  for (int y = static_cast<int>(std::floor(y0)); y < static_cast<int>(std::ceil(y1)); ++y) {
    const double cy = coverage(y, y0, y1);
    for (int x = static_cast<int>(std::floor(x0)); x < static_cast<int>(std::ceil(x1)); ++x)
      at(x, y) =
          static_cast<float>(static_cast<double>(at(x, y)) + delta * cy * coverage(x, x0, x1));
  }
}

void Canvas::blendDisc(double cx, double cy, double radius, double value, double alpha) {
  const int r = static_cast<int>(std::ceil(radius + 1.0));
  const int px = static_cast<int>(std::floor(cx)), py = static_cast<int>(std::floor(cy));
  for (int y = py - r; y <= py + r; ++y) {
    for (int x = px - r; x <= px + r; ++x) {
      const double d = std::hypot(x + 0.5 - cx, y + 0.5 - cy);
      const double w = std::clamp(radius + 0.5 - d, 0.0, 1.0);
      if (w > 0.0) blendPixel(x, y, value, alpha * w);
    }
  }
}

void Canvas::blendLine(double x0, double y0, double x1, double y1, double width, double value,
                       double alpha) {
  const double half = 0.5 * width;
  const int xa = static_cast<int>(std::floor(std::min(x0, x1) - half - 1.0));
  const int xb = static_cast<int>(std::ceil(std::max(x0, x1) + half + 1.0));
  const int ya = static_cast<int>(std::floor(std::min(y0, y1) - half - 1.0));
  const int yb = static_cast<int>(std::ceil(std::max(y0, y1) + half + 1.0));
  const double dx = x1 - x0, dy = y1 - y0, len2 = std::max(dx * dx + dy * dy, 1e-12);
  for (int y = ya; y <= yb; ++y) {
    for (int x = xa; x <= xb; ++x) {
      const double px = x + 0.5 - x0, py = y + 0.5 - y0;
      const double t = std::clamp((px * dx + py * dy) / len2, 0.0, 1.0);
      const double d = std::hypot(px - t * dx, py - t * dy);
      const double w = std::clamp(half + 0.5 - d, 0.0, 1.0);
      if (w > 0.0) blendPixel(x, y, value, alpha * w);
    }
  }
}

void Canvas::scale(double gain, double offset) {
  for (auto& v : data_) v = static_cast<float>(gain * static_cast<double>(v) + offset);
}

void Canvas::clamp(double lo, double hi) {
  for (auto& v : data_) v = static_cast<float>(std::clamp(static_cast<double>(v), lo, hi));
}

render::Texture Canvas::toTexture() const {
  render::Texture t{width_, height_, 1, {}};
  t.data.reserve(data_.size());
  for (const float v : data_)
    t.data.push_back(static_cast<std::uint8_t>(std::lround(std::clamp(v, 0.0F, 255.0F))));
  return t;
}

}  // namespace gvio::sim
