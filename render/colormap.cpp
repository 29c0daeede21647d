#include "render/colormap.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>

#include "render/render_error.hpp"

namespace gvio::render {
namespace {

// matplotlib's viridis sampled at i/15 (entries 17 i of its 256-entry table); linear
// interpolation between them stays within ~0.005 of the full table.
// clang-format off
constexpr std::array<Rgb, 16> kViridis = {{
    {0.267004F, 0.004874F, 0.329415F}, {0.282656F, 0.100196F, 0.422160F},
    {0.277134F, 0.185228F, 0.489898F}, {0.253935F, 0.265254F, 0.529983F},
    {0.221989F, 0.339161F, 0.548752F}, {0.190631F, 0.407061F, 0.556089F},
    {0.163625F, 0.471133F, 0.558148F}, {0.139147F, 0.533812F, 0.555298F},
    {0.120565F, 0.596422F, 0.543611F}, {0.134692F, 0.658636F, 0.517649F},
    {0.208030F, 0.718701F, 0.472873F}, {0.327796F, 0.773980F, 0.406640F},
    {0.477504F, 0.821444F, 0.318195F}, {0.647257F, 0.858400F, 0.209861F},
    {0.824940F, 0.884720F, 0.106217F}, {0.993248F, 0.906157F, 0.143936F},
}};
// clang-format on

Rgb viridis(double t) {
  const double x = t * static_cast<double>(kViridis.size() - 1);
  const std::size_t i = std::min(static_cast<std::size_t>(x), kViridis.size() - 2);
  const auto f = static_cast<float>(x - static_cast<double>(i));
  const Rgb& a = kViridis[i];
  const Rgb& b = kViridis[i + 1];
  return {a.r + f * (b.r - a.r), a.g + f * (b.g - a.g), a.b + f * (b.b - a.b)};
}

// MATLAB's jet: each channel a trapezoid of width 1/2 ramping over 1/4, offset by 1/4, so it
// runs dark blue, blue, cyan, yellow, red, dark red.
Rgb jet(double t) {
  const auto channel = [t](double centre) {
    return static_cast<float>(std::clamp(1.5 - std::abs(4.0 * t - centre), 0.0, 1.0));
  };
  return {channel(3.0), channel(2.0), channel(1.0)};
}

}  // namespace

Rgb colormap(ColorMap map, double t) {
  if (std::isnan(t)) return {0.5F, 0.5F, 0.5F};
  t = std::clamp(t, 0.0, 1.0);
  switch (map) {
    case ColorMap::kViridis:
      return viridis(t);
    case ColorMap::kJet:
      return jet(t);
    case ColorMap::kGray:
      break;
  }
  const auto v = static_cast<float>(t);
  return {v, v, v};
}

ColorMap parseColorMap(const std::string& name) {
  if (name == "viridis") return ColorMap::kViridis;
  if (name == "jet") return ColorMap::kJet;
  if (name == "gray") return ColorMap::kGray;
  throw RenderError("unknown colour map '" + name + "' (expected viridis, jet or gray)");
}

double normalise(double value, double lo, double hi) {
  if (!(hi > lo)) return 0.5;
  return std::clamp((value - lo) / (hi - lo), 0.0, 1.0);
}

}  // namespace gvio::render
