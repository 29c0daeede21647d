#pragma once
// 2-D overlays (title, legend, colour bar, scale bar, north arrow) drawn with cairo onto a
// rendered map. Every size scales with the image, so a 320x240 preview and a 4K still both read.
#include <optional>
#include <string>
#include <vector>

#include "render/colormap.hpp"
#include "render/image.hpp"

namespace gvio::render {

struct LegendEntry {
  std::string label;
  Rgb color;
  bool dashed = false;
};

struct Annotations {
  std::string title;                // centred at the top; empty: none
  std::vector<LegendEntry> legend;  // box at the top left; empty: none

  struct ColorBar {
    ColorMap map = ColorMap::kViridis;
    double lo = 0.0, hi = 1.0;  // values at the bar's bottom and top (finite)
    std::string label;          // above the bar, e.g. "height (m)"
  };
  std::optional<ColorBar> color_bar;  // vertical bar at the right edge with 5 tick labels

  // > 0: a metric scale bar at the bottom left, about 1/5 of the width long.
  double metres_per_pixel = 0.0;
  // Direction of north in the image, degrees clockwise from up: a compass needle at the top right.
  std::optional<double> north_deg;
};

// The unit every overlay length is a multiple of (1/60 of the image's shorter side, at least
// 7 px): the compass and colour bar column at the right edge stays within 10 units of it, the
// title strip at the top within 5 (so views can keep their content clear of them).
double annotationUnitPx(int width, int height);

// Draws `a` onto `image` in place; pixels no overlay touches keep their exact bytes. Throws
// RenderError on an empty or inconsistent image, or on a non-finite colour bar range, scale or
// north direction.
void annotate(ImageRgba& image, const Annotations& a);

// The scale bar's length: the largest 1, 2 or 5 x 10^k metres not above `target_m` (> 0).
double niceLength(double target_m);

// A distance as the scale bar labels it: "2 km", "50 m", "20 cm", "5 mm".
std::string formatDistance(double metres);

}  // namespace gvio::render
