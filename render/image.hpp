#pragma once
// A CPU-side image as the renderer returns it: rows top to bottom (OpenCV order), tightly packed.
#include <cstdint>
#include <vector>

namespace gvio::render {

struct ImageRgba {
  int width = 0, height = 0;
  std::vector<std::uint8_t> rgba;  // width * height * 4

  [[nodiscard]] const std::uint8_t* pixel(int x, int y) const {
    return rgba.data() + (static_cast<std::size_t>(y) * static_cast<std::size_t>(width) +
                          static_cast<std::size_t>(x)) *
                             4;
  }
};

// Metric depth along the camera's viewing axis (z in the camera frame), 0 where nothing was drawn.
struct DepthImage {
  int width = 0, height = 0;
  std::vector<float> z_m;

  [[nodiscard]] float at(int x, int y) const {
    return z_m[static_cast<std::size_t>(y) * static_cast<std::size_t>(width) +
               static_cast<std::size_t>(x)];
  }
};

}  // namespace gvio::render
