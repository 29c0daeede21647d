#include "render/annotate.hpp"

#include <cairo.h>
#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <memory>
#include <numbers>

#include "render/render_error.hpp"

namespace gvio::render {
double annotationUnitPx(int width, int height) {
  return std::max(std::min(width, height) / 60.0, 7.0);
}

namespace {

constexpr Rgb kInk{0.1F, 0.1F, 0.1F};
constexpr Rgb kNorthRed{0.8F, 0.1F, 0.1F};
constexpr double kPi = std::numbers::pi;

// Every length derives from `base`, 1/60 of the image's shorter side, floored so that text on a
// thumbnail stays legible.
struct Style {
  double base, margin, pad, text, title;  // text and title: font sizes
  double line;                            // outlines and ticks
};

Style styleFor(int width, int height) {
  const double base = annotationUnitPx(width, height);
  return {base, base, 0.6 * base, 1.4 * base, 1.9 * base, std::max(1.0, 0.1 * base)};
}

// ---- RGBA <-> cairo's native-endian premultiplied ARGB32 -------------------------------------

std::uint32_t premultipliedArgb(const std::uint8_t* rgba) {
  const std::uint32_t a = rgba[3];
  const auto mul = [a](std::uint32_t c) { return (c * a + 127) / 255; };
  return a << 24 | mul(rgba[0]) << 16 | mul(rgba[1]) << 8 | mul(rgba[2]);
}

void storeStraight(std::uint32_t argb, std::uint8_t* rgba) {
  const std::uint32_t a = argb >> 24;
  const auto div = [a](std::uint32_t p) {
    return static_cast<std::uint8_t>(a == 0 ? 0 : std::min(255U, (p * 255 + a / 2) / a));
  };
  rgba[0] = div(argb >> 16 & 0xFFU);
  rgba[1] = div(argb >> 8 & 0xFFU);
  rgba[2] = div(argb & 0xFFU);
  rgba[3] = static_cast<std::uint8_t>(a);
}

struct CairoPixels {
  int stride = 0;
  std::vector<unsigned char> data;
};

// Calls f(rgba, argb) with each pixel's 4 bytes in the image and in the cairo buffer.
template <typename F>
void forEachPixel(ImageRgba& image, CairoPixels& px, F f) {
  const auto width = static_cast<std::size_t>(image.width);
  for (std::size_t y = 0; y < static_cast<std::size_t>(image.height); ++y) {
    std::uint8_t* rgba = image.rgba.data() + y * width * 4;
    unsigned char* argb = px.data.data() + y * static_cast<std::size_t>(px.stride);
    for (std::size_t x = 0; x < width; ++x, rgba += 4, argb += 4) f(rgba, argb);
  }
}

CairoPixels toCairo(ImageRgba& image) {
  CairoPixels px;
  px.stride = cairo_format_stride_for_width(CAIRO_FORMAT_ARGB32, image.width);
  if (px.stride < 0) throw RenderError(fmt::format("image too wide to annotate: {}", image.width));
  px.data.resize(static_cast<std::size_t>(px.stride) * static_cast<std::size_t>(image.height));
  forEachPixel(image, px, [](const std::uint8_t* rgba, unsigned char* argb) {
    const std::uint32_t word = premultipliedArgb(rgba);
    std::memcpy(argb, &word, sizeof word);
  });
  return px;
}

// Premultiplication loses colour precision in translucent pixels, so only pixels that drawing
// changed are converted back; the rest keep their original bytes.
void fromCairo(CairoPixels& px, ImageRgba& image) {
  forEachPixel(image, px, [](std::uint8_t* rgba, const unsigned char* argb) {
    std::uint32_t word = 0;
    std::memcpy(&word, argb, sizeof word);
    if (word != premultipliedArgb(rgba)) storeStraight(word, rgba);
  });
}

// ---- drawing primitives ----------------------------------------------------------------------

void setColour(cairo_t* cr, Rgb c, double alpha = 1.0) {
  cairo_set_source_rgba(cr, c.r, c.g, c.b, alpha);
}

// Translucent white with a faint edge under the current path: keeps dark text readable on any
// background while the map still shows through.
void fillBackdrop(cairo_t* cr, const Style& s) {
  cairo_set_source_rgba(cr, 1.0, 1.0, 1.0, 0.8);
  cairo_fill_preserve(cr);
  cairo_set_source_rgba(cr, 0.0, 0.0, 0.0, 0.3);
  cairo_set_line_width(cr, std::max(1.0, 0.08 * s.base));
  cairo_stroke(cr);
}

void backdrop(cairo_t* cr, const Style& s, double x, double y, double w, double h) {
  const double r = std::min({0.6 * s.base, 0.5 * w, 0.5 * h});
  cairo_new_sub_path(cr);
  cairo_arc(cr, x + w - r, y + r, r, -0.5 * kPi, 0.0);
  cairo_arc(cr, x + w - r, y + h - r, r, 0.0, 0.5 * kPi);
  cairo_arc(cr, x + r, y + h - r, r, 0.5 * kPi, kPi);
  cairo_arc(cr, x + r, y + r, r, kPi, 1.5 * kPi);
  cairo_close_path(cr);
  fillBackdrop(cr, s);
}

// Selects the font and returns its line height (ascent + descent).
double useFont(cairo_t* cr, double size, bool bold = false) {
  cairo_select_font_face(cr, "sans-serif", CAIRO_FONT_SLANT_NORMAL,
                         bold ? CAIRO_FONT_WEIGHT_BOLD : CAIRO_FONT_WEIGHT_NORMAL);
  cairo_set_font_size(cr, size);
  cairo_font_extents_t fe;
  cairo_font_extents(cr, &fe);
  return fe.ascent + fe.descent;
}

double textWidth(cairo_t* cr, const std::string& text) {
  cairo_text_extents_t te;
  cairo_text_extents(cr, text.c_str(), &te);
  return te.x_advance;
}

// Draws `text` with the top of its line box at `top`.
void showText(cairo_t* cr, double x, double top, const std::string& text, Rgb c = kInk) {
  cairo_font_extents_t fe;
  cairo_font_extents(cr, &fe);
  setColour(cr, c);
  cairo_move_to(cr, x, top + fe.ascent);
  cairo_show_text(cr, text.c_str());
}

// ---- the overlays; those at the top return the y just below them
// ---------------------------------

double drawTitle(cairo_t* cr, const Style& s, int width, const std::string& title) {
  useFont(cr, s.title, true);
  // Long titles shrink rather than run off the image.
  const double room = width - 2.0 * (s.margin + s.pad), natural = textWidth(cr, title);
  const double line_h = useFont(cr, natural > room ? s.title * room / natural : s.title, true);
  const double w = textWidth(cr, title), x = 0.5 * (width - w);
  backdrop(cr, s, x - s.pad, s.margin, w + 2.0 * s.pad, line_h + 2.0 * s.pad);
  showText(cr, x, s.margin + s.pad, title);
  return s.margin + line_h + 2.0 * s.pad;
}

void drawLegend(cairo_t* cr, const Style& s, double top, const std::vector<LegendEntry>& legend) {
  const double line_h = useFont(cr, s.text), gap = 0.35 * s.base, sample = 2.6 * s.base;
  double label_w = 0.0;
  for (const LegendEntry& e : legend) label_w = std::max(label_w, textWidth(cr, e.label));
  const auto n = static_cast<double>(legend.size());
  backdrop(cr, s, s.margin, top, 2.0 * s.pad + sample + 0.6 * s.base + label_w,
           2.0 * s.pad + n * line_h + (n - 1.0) * gap);
  const double x = s.margin + s.pad;
  double y = top + s.pad;
  for (const LegendEntry& e : legend) {
    const std::array<double, 2> dashes = {0.9 * s.base, 0.5 * s.base};
    cairo_set_dash(cr, dashes.data(), e.dashed ? 2 : 0, 0.0);
    cairo_set_line_width(cr, 0.3 * s.base);
    cairo_set_line_cap(cr, CAIRO_LINE_CAP_BUTT);
    setColour(cr, e.color);
    cairo_move_to(cr, x, y + 0.5 * line_h);
    cairo_line_to(cr, x + sample, y + 0.5 * line_h);
    cairo_stroke(cr);
    cairo_set_dash(cr, nullptr, 0, 0.0);
    showText(cr, x + sample + 0.6 * s.base, y, e.label);
    y += line_h + gap;
  }
}

// A compass needle in a disc, its red half and the "N" pointing north.
double drawNorth(cairo_t* cr, const Style& s, int width, double top, double north_deg) {
  const double r = 3.2 * s.base, cx = width - s.margin - r, cy = top + r;
  const double th = north_deg * kPi / 180.0, dx = std::sin(th), dy = -std::cos(th);
  const double half = 0.18 * r;  // half the needle's width
  cairo_new_sub_path(cr);
  cairo_arc(cr, cx, cy, r, 0.0, 2.0 * kPi);
  fillBackdrop(cr, s);
  for (const double sign : {1.0, -1.0}) {
    cairo_move_to(cr, cx + sign * 0.52 * r * dx, cy + sign * 0.52 * r * dy);
    cairo_line_to(cr, cx - half * dy, cy + half * dx);
    cairo_line_to(cr, cx + half * dy, cy - half * dx);
    cairo_close_path(cr);
    setColour(cr, sign > 0.0 ? kNorthRed : Rgb{1.0F, 1.0F, 1.0F});
    cairo_fill_preserve(cr);
    setColour(cr, kInk);
    cairo_set_line_width(cr, s.line);
    cairo_set_line_join(cr, CAIRO_LINE_JOIN_ROUND);
    cairo_stroke(cr);
  }
  useFont(cr, 1.2 * s.base, true);
  cairo_text_extents_t te;
  cairo_text_extents(cr, "N", &te);
  const double lx = cx + 0.75 * r * dx, ly = cy + 0.75 * r * dy;
  setColour(cr, kInk);
  cairo_move_to(cr, lx - te.x_bearing - 0.5 * te.width, ly - te.y_bearing - 0.5 * te.height);
  cairo_show_text(cr, "N");
  return cy + r;
}

// Tick labels with as few decimals as show every tick exactly, at most one digit below the
// step's leading digit (so 0..1 reads 0.00, 0.25, ... and 0..4 reads 0, 1, ...).
std::vector<std::string> tickLabels(const std::vector<double>& ticks, double step) {
  const int most =
      step > 0.0 ? std::clamp(1 - static_cast<int>(std::floor(std::log10(step))), 0, 6) : 0;
  int decimals = 0;
  const auto exact = [&decimals](double v) {
    const double scaled = v * std::pow(10.0, decimals);
    return std::abs(scaled - std::round(scaled)) < 1e-6;
  };
  while (decimals < most && !std::all_of(ticks.begin(), ticks.end(), exact)) ++decimals;
  std::vector<std::string> labels;
  for (double v : ticks) labels.push_back(fmt::format("{:.{}f}", v, decimals));
  return labels;
}

// The colour map top (1) to bottom (0) in the pixel-aligned box x, y, w, h, one row at a time so
// that every row is exactly one map colour.
void drawGradient(cairo_t* cr, const Style& s, ColorMap map, bool flat, double x, double y,
                  double w, double h) {
  for (int row = 0; row < static_cast<int>(h); ++row) {
    setColour(cr, colormap(map, flat ? 0.5 : 1.0 - (row + 0.5) / h));
    cairo_rectangle(cr, x, y + row, w, 1.0);
    cairo_fill(cr);
  }
  // Outline outside the bar so that its end rows keep the map's end colours.
  setColour(cr, kInk);
  cairo_set_line_width(cr, s.line);
  cairo_rectangle(cr, x - 0.5 * s.line, y - 0.5 * s.line, w + s.line, h + s.line);
  cairo_stroke(cr);
}

void drawColorBar(cairo_t* cr, const Style& s, int width, int height, double top,
                  const Annotations::ColorBar& bar) {
  const bool flat = !(bar.hi > bar.lo);  // normalise() maps everything to the middle colour
  std::vector<double> ticks;
  for (int i = 0; i <= (flat ? 0 : 4); ++i) ticks.push_back(bar.lo + 0.25 * i * (bar.hi - bar.lo));
  const double line_h = useFont(cr, s.text);
  const std::vector<std::string> labels = tickLabels(ticks, 0.25 * (bar.hi - bar.lo));
  double tick_w = 0.0;
  for (const std::string& l : labels) tick_w = std::max(tick_w, textWidth(cr, l));
  const double bar_w = std::round(1.3 * s.base), tick_len = 0.4 * s.base, gap = 0.3 * s.base;
  const double title_w = bar.label.empty() ? 0.0 : textWidth(cr, bar.label);
  const double title_h = bar.label.empty() ? 0.0 : line_h + 0.4 * s.base;
  const double box_w = std::max(title_w, bar_w + tick_len + gap + tick_w) + 2.0 * s.pad;
  const double box_x = width - s.margin - box_w;
  // Half a tick label sticks out past each end of the bar.
  const double bar_top = std::round(top + s.pad + title_h + 0.5 * line_h);
  const double room = height - s.margin - s.pad - 0.5 * line_h - bar_top;
  const double bar_h = std::round(std::min(room, std::max(0.4 * height, 8.0 * s.base)));
  if (bar_h < 2.0 * s.base) return;  // no room on a tiny image
  backdrop(cr, s, box_x, top, box_w, bar_top + bar_h + 0.5 * line_h + s.pad - top);
  if (!bar.label.empty()) showText(cr, box_x + 0.5 * (box_w - title_w), top + s.pad, bar.label);
  const double bar_x = std::round(box_x + s.pad);
  drawGradient(cr, s, bar.map, flat, bar_x, bar_top, bar_w, bar_h);
  cairo_set_line_width(cr, s.line);
  for (std::size_t i = 0; i < ticks.size(); ++i) {
    const double y = bar_top + bar_h * (flat ? 0.5 : 1.0 - 0.25 * static_cast<double>(i));
    cairo_move_to(cr, bar_x + bar_w, y);
    cairo_line_to(cr, bar_x + bar_w + tick_len, y);
    cairo_stroke(cr);
    showText(cr, bar_x + bar_w + tick_len + gap, y - 0.5 * line_h, labels[i]);
  }
}

// A map-style bar of alternating dark and white quarters with its length above it.
void drawScaleBar(cairo_t* cr, const Style& s, int width, int height, double metres_per_pixel) {
  const double metres = niceLength(0.2 * width * metres_per_pixel);
  const double len = metres / metres_per_pixel, bar_h = 0.6 * s.base;
  const std::string label = formatDistance(metres);
  const double line_h = useFont(cr, s.text), label_w = textWidth(cr, label);
  const double box_h = 2.0 * s.pad + line_h + 0.3 * s.base + bar_h;
  const double box_y = height - s.margin - box_h;
  backdrop(cr, s, s.margin, box_y, std::max(len, label_w) + 2.0 * s.pad, box_h);
  const double x = s.margin + s.pad + 0.5 * std::max(0.0, label_w - len);
  const double y = height - s.margin - s.pad - bar_h;
  for (int q = 0; q < 4; ++q) {
    setColour(cr, q % 2 == 0 ? kInk : Rgb{1.0F, 1.0F, 1.0F});
    cairo_rectangle(cr, x + 0.25 * q * len, y, 0.25 * len, bar_h);
    cairo_fill(cr);
  }
  setColour(cr, kInk);
  cairo_set_line_width(cr, s.line);
  cairo_rectangle(cr, x, y, len, bar_h);
  cairo_stroke(cr);
  showText(cr, x + 0.5 * (len - label_w), box_y + s.pad, label);
}

void drawAll(cairo_t* cr, const Style& s, int width, int height, const Annotations& a) {
  double top = s.margin;
  if (!a.title.empty()) top = drawTitle(cr, s, width, a.title) + 0.5 * s.margin;
  if (!a.legend.empty()) drawLegend(cr, s, top, a.legend);
  double right_top = top;
  if (a.north_deg) right_top = drawNorth(cr, s, width, top, *a.north_deg) + 0.5 * s.margin;
  if (a.color_bar) drawColorBar(cr, s, width, height, right_top, *a.color_bar);
  if (a.metres_per_pixel > 0.0) drawScaleBar(cr, s, width, height, a.metres_per_pixel);
}

void requireFinite(double value, const char* what) {
  if (!std::isfinite(value)) throw RenderError(fmt::format("annotation {} is {}", what, value));
}

void validate(const ImageRgba& image, const Annotations& a) {
  const bool sized = image.width > 0 && image.height > 0 &&
                     image.rgba.size() == 4 * static_cast<std::size_t>(image.width) *
                                              static_cast<std::size_t>(image.height);
  if (!sized) {
    throw RenderError(fmt::format("cannot annotate a {}x{} image holding {} bytes", image.width,
                                  image.height, image.rgba.size()));
  }
  if (a.color_bar) {
    requireFinite(a.color_bar->lo, "colour bar low end");
    requireFinite(a.color_bar->hi, "colour bar high end");
  }
  requireFinite(a.metres_per_pixel, "scale (m/px)");
  if (a.north_deg) requireFinite(*a.north_deg, "north direction (deg)");
}

bool isEmpty(const Annotations& a) {
  return a.title.empty() && a.legend.empty() && !a.color_bar && !(a.metres_per_pixel > 0.0) &&
         !a.north_deg;
}

}  // namespace

void annotate(ImageRgba& image, const Annotations& a) {
  validate(image, a);
  if (isEmpty(a)) return;
  CairoPixels px = toCairo(image);
  {
    using SurfacePtr = std::unique_ptr<cairo_surface_t, decltype(&cairo_surface_destroy)>;
    using ContextPtr = std::unique_ptr<cairo_t, decltype(&cairo_destroy)>;
    SurfacePtr surface(cairo_image_surface_create_for_data(px.data.data(), CAIRO_FORMAT_ARGB32,
                                                           image.width, image.height, px.stride),
                       &cairo_surface_destroy);
    ContextPtr cr(cairo_create(surface.get()), &cairo_destroy);
    if (cairo_status(cr.get()) != CAIRO_STATUS_SUCCESS) {
      throw RenderError(std::string("cairo: ") + cairo_status_to_string(cairo_status(cr.get())));
    }
    drawAll(cr.get(), styleFor(image.width, image.height), image.width, image.height, a);
    cairo_surface_flush(surface.get());
  }
  fromCairo(px, image);
}

double niceLength(double target_m) {
  if (!(target_m > 0.0) || !std::isfinite(target_m)) {
    throw RenderError(fmt::format("no scale bar length for {} m", target_m));
  }
  double decade = std::pow(10.0, std::floor(std::log10(target_m)));
  if (10.0 * decade <= target_m) decade *= 10.0;  // log10 rounding just below an exact power
  for (const double m : {5.0, 2.0}) {
    if (m * decade <= target_m) return m * decade;
  }
  return decade;
}

std::string formatDistance(double metres) {
  if (metres >= 1000.0) return fmt::format("{:g} km", metres / 1000.0);
  if (metres >= 1.0) return fmt::format("{:g} m", metres);
  if (metres >= 0.01) return fmt::format("{:g} cm", metres * 100.0);
  return fmt::format("{:g} mm", metres * 1000.0);
}

}  // namespace gvio::render
