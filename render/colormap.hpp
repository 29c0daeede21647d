#pragma once
// Colour maps that turn a scalar (height, error, time) into a colour for maps and colour bars.
#include <string>

namespace gvio::render {

struct Rgb {
  float r = 0.0F, g = 0.0F, b = 0.0F;  // each 0..1
};

enum class ColorMap { kViridis, kJet, kGray };

// The colour of `t` in `map`; t is clamped to [0, 1] and NaN gives mid grey, so a missing value
// stands out from every valid one in viridis and jet.
Rgb colormap(ColorMap map, double t);

// "viridis", "jet" or "gray"; anything else throws RenderError naming the accepted values.
ColorMap parseColorMap(const std::string& name);

// Maps `value` linearly onto [0, 1] between lo and hi, clamped. hi <= lo (a constant field, or
// NaN bounds) gives 0.5 everywhere; a NaN value stays NaN so colormap() shows it as grey.
double normalise(double value, double lo, double hi);

}  // namespace gvio::render
