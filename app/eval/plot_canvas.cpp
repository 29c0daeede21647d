#include "eval/plot_canvas.hpp"

#include <cairo-svg.h>

#include <algorithm>
#include <cstdio>
#include <memory>
#include <numbers>
#include <stdexcept>

#include "io/atomic_write.hpp"
#include "render/colormap.hpp"

namespace gvio::eval::canvas {
namespace {

// The 1, 2 or 5 x 10^k step closest to `raw` (> 0).
double niceStep(double raw) {
  const double mag = std::pow(10.0, std::floor(std::log10(raw)));
  const double f = raw / mag;
  return (f < 1.5 ? 1.0 : f < 3.5 ? 2.0 : f < 7.5 ? 5.0 : 10.0) * mag;
}

void drawSwatch(cairo_t* cr, double x, double y, const LegendEntry& e) {
  if (e.swatch == Swatch::kBand) {
    setColour(cr, e.colour, 0.3);
    cairo_rectangle(cr, x, y - 7.0, 28.0, 14.0);
    cairo_fill(cr);
    return;
  }
  cairo_set_line_width(cr, 3.0);
  if (e.swatch == Swatch::kDashed) dash(cr, 7.0, 4.0);
  const int pieces = e.swatch == Swatch::kGradient ? 7 : 1;
  for (int i = 0; i < pieces; ++i) {
    setColour(cr, e.swatch == Swatch::kGradient ? viridis(i / 6.0) : e.colour);
    line(cr, x + 28.0 * i / pieces, y, x + 28.0 * (i + 1) / pieces, y);
    cairo_stroke(cr);
  }
  dash(cr, 0.0, 0.0);
}

using SurfacePtr = std::unique_ptr<cairo_surface_t, decltype(&cairo_surface_destroy)>;

cairo_status_t appendToString(void* closure, const unsigned char* data, unsigned int length) {
  try {
    static_cast<std::string*>(closure)->append(reinterpret_cast<const char*>(data), length);
    return CAIRO_STATUS_SUCCESS;
  } catch (...) {
    return CAIRO_STATUS_WRITE_ERROR;
  }
}

void check(cairo_status_t status) {
  if (status != CAIRO_STATUS_SUCCESS)
    throw std::runtime_error(std::string("cairo: ") + cairo_status_to_string(status));
}

void drawOn(cairo_surface_t* surface, const DrawFn& draw) {
  check(cairo_surface_status(surface));
  const std::unique_ptr<cairo_t, decltype(&cairo_destroy)> cr(cairo_create(surface),
                                                              &cairo_destroy);
  cairo_set_source_rgb(cr.get(), 1.0, 1.0, 1.0);
  cairo_paint(cr.get());
  draw(cr.get(), kWidth, kHeight);
  check(cairo_status(cr.get()));
}

std::string renderPng(const DrawFn& draw) {
  SurfacePtr surface(cairo_image_surface_create(CAIRO_FORMAT_RGB24, kWidth, kHeight),
                     &cairo_surface_destroy);
  drawOn(surface.get(), draw);
  std::string bytes;
  check(cairo_surface_write_to_png_stream(surface.get(), appendToString, &bytes));
  return bytes;
}

std::string renderSvg(const DrawFn& draw) {
  std::string bytes;
  SurfacePtr surface(cairo_svg_surface_create_for_stream(appendToString, &bytes, kWidth, kHeight),
                     &cairo_surface_destroy);
  cairo_svg_surface_set_document_unit(surface.get(), CAIRO_SVG_UNIT_PX);  // 1200x900 px, not pt
  drawOn(surface.get(), draw);
  cairo_surface_finish(surface.get());  // flushes the document into `bytes`
  check(cairo_surface_status(surface.get()));
  return bytes;
}

}  // namespace

Rgb viridis(double u) {
  const render::Rgb c = render::colormap(render::ColorMap::kViridis, std::isfinite(u) ? u : 0.0);
  return {static_cast<double>(c.r), static_cast<double>(c.g), static_cast<double>(c.b)};
}

void setColour(cairo_t* cr, Rgb c, double alpha) {
  cairo_set_source_rgba(cr, c.r, c.g, c.b, alpha);
}

void line(cairo_t* cr, double x0, double y0, double x1, double y1) {
  cairo_move_to(cr, x0, y0);
  cairo_line_to(cr, x1, y1);
}

// Dashes of `on` px with `off` px gaps; on = 0 for solid lines.
void dash(cairo_t* cr, double on, double off) {
  const std::array<double, 2> pattern = {on, off};
  cairo_set_dash(cr, pattern.data(), on > 0.0 ? 2 : 0, 0.0);
}

// Min/max of the finite values (0..0 when there are none).
Range rangeOf(const std::vector<double>& values) {
  Range r{INFINITY, -INFINITY};
  for (double v : values) {
    if (std::isfinite(v)) r = {std::min(r.lo, v), std::max(r.hi, v)};
  }
  return r.lo <= r.hi ? r : Range{0.0, 0.0};
}

// Widens `r` by `fraction` of its span on each side; a (numerically) empty range becomes
// mid +- degenerate_half so no axis ever has zero extent.
Range padded(Range r, double fraction, double degenerate_half) {
  const double scale = std::max({1.0, std::abs(r.lo), std::abs(r.hi)});
  if (!(r.span() > 1e-9 * scale)) return {r.mid() - degenerate_half, r.mid() + degenerate_half};
  return {r.lo - fraction * r.span(), r.hi + fraction * r.span()};
}

// The largest 1, 2 or 5 x 10^k not above `x` (> 0).
double niceFloor(double x) {
  const double mag = std::pow(10.0, std::floor(std::log10(x)));
  const double f = x / mag;
  return (f >= 5.0 ? 5.0 : f >= 2.0 ? 2.0 : 1.0) * mag;
}

// Multiples of `step` inside `r`, counted in integers so a step below the values' resolution
// cannot loop forever.
std::vector<double> ticks(Range r, double step) {
  std::vector<double> out;
  const double first = std::ceil(r.lo / step - 1e-9), last = std::floor(r.hi / step + 1e-9);
  for (double k = first; k <= last && out.size() < 64; k += 1.0) out.push_back(k * step);
  return out;
}
// A nice step giving about `count` intervals over `r`.
double stepFor(Range r, int count) {
  return niceStep(r.span() / count);
}

std::string tickLabel(double v, double step) {
  const int decimals = std::clamp(static_cast<int>(-std::floor(std::log10(step) + 1e-9)), 0, 9);
  if (std::abs(v) < 1e-6 * step) v = 0.0;  // no "-0"
  char buf[48];
  std::snprintf(buf, sizeof(buf), "%.*f", decimals, v);
  return buf;
}

std::string formatValue(double v) {
  char buf[48];
  std::snprintf(buf, sizeof(buf), "%#.4g", v);
  return buf;
}

// Draws `s` anchored at (x, y): ax/ay = 0, 0.5, 1 for left/centre/right and top/middle/baseline
// (vertical alignment on the cap height, so labels line up whatever their letters), rotated by
// `angle` about the anchor. Returns the advance width; x = NaN only measures.
double text(cairo_t* cr, const std::string& s, double x, double y, double ax, double ay,
            double size, bool bold, double angle) {
  cairo_save(cr);
  cairo_select_font_face(cr, "sans-serif", CAIRO_FONT_SLANT_NORMAL,
                         bold ? CAIRO_FONT_WEIGHT_BOLD : CAIRO_FONT_WEIGHT_NORMAL);
  cairo_set_font_size(cr, size);
  cairo_text_extents_t e;
  cairo_text_extents(cr, s.c_str(), &e);
  if (std::isnan(x)) {  // measure only
    cairo_restore(cr);
    return e.x_advance;
  }
  cairo_translate(cr, x, y);
  cairo_rotate(cr, angle);
  cairo_move_to(cr, -ax * e.x_advance, (1.0 - ay) * 0.72 * size);
  cairo_show_text(cr, s.c_str());
  cairo_restore(cr);
  cairo_new_path(cr);  // show_text leaves a current point that the next path would start from
  return e.x_advance;
}

void drawTitle(cairo_t* cr, double width, const std::string& title) {
  double size = 20.0;
  while (size > 10.0 && text(cr, title, NAN, 0.0, 0.0, 0.0, size, true) > width - 40.0) size -= 1;
  setColour(cr, kInk);
  text(cr, title, width / 2.0, kTitleTop, 0.5, 0.0, size, true);
}

void drawGrid(cairo_t* cr, const Frame& f, double xstep, double ystep) {
  setColour(cr, kGrid);
  cairo_set_line_width(cr, 1.0);
  for (double v : ticks(f.xr, xstep)) line(cr, f.sx(v), f.y, f.sx(v), f.y + f.h);
  for (double v : ticks(f.yr, ystep)) line(cr, f.x, f.sy(v), f.x + f.w, f.sy(v));
  cairo_stroke(cr);
}

// Frame outline, x ticks (labelled when `label` is non-empty) and y ticks with a rotated label.
void drawAxes(cairo_t* cr, const Frame& f, double xstep, double ystep, const std::string& xlabel,
              const std::string& ylabel) {
  setColour(cr, kInk);
  cairo_set_line_width(cr, 1.0);
  cairo_rectangle(cr, std::round(f.x) + 0.5, std::round(f.y) + 0.5, std::round(f.w),
                  std::round(f.h));
  cairo_stroke(cr);
  for (double v : ticks(f.xr, xstep)) {
    line(cr, f.sx(v), f.y + f.h, f.sx(v), f.y + f.h + 5.0);
    cairo_stroke(cr);
    if (!xlabel.empty()) text(cr, tickLabel(v, xstep), f.px(v), f.y + f.h + 10.0, 0.5, 0.0, kTick);
  }
  if (!xlabel.empty()) text(cr, xlabel, f.x + f.w / 2.0, f.y + f.h + 38.0, 0.5, 0.0, kLabel);
  double widest = 0.0;
  for (double v : ticks(f.yr, ystep)) {
    line(cr, f.x - 5.0, f.sy(v), f.x, f.sy(v));
    cairo_stroke(cr);
    widest = std::max(widest, text(cr, tickLabel(v, ystep), f.x - 8.0, f.py(v), 1.0, 0.5, kTick));
  }
  text(cr, ylabel, f.x - 16.0 - widest, f.y + f.h / 2.0, 0.5, 1.0, kLabel, false,
       -std::numbers::pi / 2.0);
}

// One row of legend entries starting at (x, y).
void drawLegend(cairo_t* cr, double x, double y, const std::vector<LegendEntry>& entries) {
  for (const LegendEntry& e : entries) {
    drawSwatch(cr, x, y, e);
    setColour(cr, kInk);
    x += 36.0 + text(cr, e.label, x + 36.0, y, 0.0, 0.5, kLabel) + 28.0;
  }
}

// A polyline of (xs, ys); a single sample is drawn as a dot.
void drawCurve(cairo_t* cr, const Frame& f, const std::vector<double>& xs,
               const std::vector<double>& ys, Rgb colour, double width, bool dashed) {
  cairo_new_path(cr);
  setColour(cr, colour);
  if (dashed) dash(cr, 9.0, 6.0);
  cairo_set_line_width(cr, width);
  cairo_set_line_join(cr, CAIRO_LINE_JOIN_ROUND);
  if (xs.size() == 1) {
    cairo_arc(cr, f.px(xs[0]), f.py(ys[0]), 3.0, 0.0, 2.0 * std::numbers::pi);
    cairo_fill(cr);
    return;
  }
  for (std::size_t i = 0; i < xs.size(); ++i) cairo_line_to(cr, f.px(xs[i]), f.py(ys[i]));
  cairo_stroke(cr);
  dash(cr, 0.0, 0.0);
}

std::vector<double> component(const std::vector<Eigen::Vector3d>& p, int axis) {
  std::vector<double> out;
  out.reserve(p.size());
  for (const Eigen::Vector3d& v : p) out.push_back(v[axis]);
  return out;
}

Frame equalAspectFrame(double x, double y, double w, double h,
                       const std::vector<Eigen::Vector3d>& points, std::array<int, 2> plane) {
  Range xr = rangeOf(component(points, plane[0])), yr = rangeOf(component(points, plane[1]));
  const double pad = 0.05 * std::max(xr.span(), yr.span());
  xr = padded({xr.lo - pad, xr.hi + pad}, 0.0, 1.0);
  yr = padded({yr.lo - pad, yr.hi + pad}, 0.0, 1.0);
  const double metres_per_px = std::max(xr.span() / w, yr.span() / h);
  xr = {xr.mid() - 0.5 * w * metres_per_px, xr.mid() + 0.5 * w * metres_per_px};
  yr = {yr.mid() - 0.5 * h * metres_per_px, yr.mid() + 0.5 * h * metres_per_px};
  return {x, y, w, h, xr, yr};
}

void drawColourBar(cairo_t* cr, double x, double y, double h, Range err, const std::string& label) {
  constexpr double kBarW = 22.0;
  cairo_pattern_t* gradient = cairo_pattern_create_linear(0.0, y + h, 0.0, y);
  constexpr int kStops = 32;
  for (int i = 0; i <= kStops; ++i) {
    const Rgb c = viridis(static_cast<double>(i) / kStops);
    cairo_pattern_add_color_stop_rgb(gradient, static_cast<double>(i) / kStops, c.r, c.g, c.b);
  }
  cairo_rectangle(cr, x, y, kBarW, h);
  cairo_set_source(cr, gradient);
  cairo_fill_preserve(cr);
  cairo_pattern_destroy(gradient);
  setColour(cr, kInk);
  cairo_set_line_width(cr, 1.0);
  cairo_stroke(cr);
  double widest =
      std::max(text(cr, "max " + formatValue(err.hi), x + kBarW + 6.0, y, 0.0, 0.5, kTick),
               text(cr, "min " + formatValue(err.lo), x + kBarW + 6.0, y + h, 0.0, 0.5, kTick));
  if (err.span() > 0.0) {
    const double step = stepFor(err, 5);
    for (double v : ticks(err, step)) {
      const double py = y + h - (v - err.lo) / err.span() * h;
      if (py < y + 24.0 || py > y + h - 24.0) continue;  // keep clear of the min/max labels
      line(cr, x + kBarW - 5.0, py, x + kBarW, py);
      cairo_stroke(cr);
      widest = std::max(widest, text(cr, tickLabel(v, step), x + kBarW + 6.0, py, 0, 0.5, kTick));
    }
  }
  text(cr, label, x + kBarW + 14.0 + widest, y + h / 2.0, 0.5, 0.0, kLabel, false,
       -std::numbers::pi / 2.0);
}

void drawScaleBar(cairo_t* cr, const Frame& f, const std::vector<Eigen::Vector3d>& avoid,
                  std::array<int, 2> plane) {
  const double metres = niceFloor(f.xr.span() / 5.0), len = metres / f.xr.span() * f.w;
  const double box_w = len + 40.0, box_h = 54.0;
  // Candidate boxes: bottom-left, bottom-right, top-left, top-right.
  const double left = f.x + 12.0, right = f.x + f.w - 12.0 - box_w;
  const double bottom = f.y + f.h - 12.0 - box_h, top = f.y + 12.0;
  const std::array<std::array<double, 2>, 4> corners = {
      {{left, bottom}, {right, bottom}, {left, top}, {right, top}}};
  std::array<int, 4> hits{};
  for (const Eigen::Vector3d& p : avoid) {
    const double px = f.px(p[plane[0]]), py = f.py(p[plane[1]]);
    for (std::size_t c = 0; c < 4; ++c) {
      const auto [cx, cy] = corners[c];
      hits[c] += std::abs(px - cx - box_w / 2) < box_w / 2 + 15 &&
                 std::abs(py - cy - box_h / 2) < box_h / 2 + 15;
    }
  }
  const auto [bx, by] = corners[std::min_element(hits.begin(), hits.end()) - hits.begin()];
  cairo_set_source_rgba(cr, 1.0, 1.0, 1.0, 0.85);
  cairo_rectangle(cr, bx, by, box_w, box_h);
  cairo_fill(cr);
  setColour(cr, kInk);
  cairo_set_line_width(cr, 3.0);
  line(cr, bx + 20.0, by + box_h - 16.0, bx + 20.0 + len, by + box_h - 16.0);
  cairo_stroke(cr);
  cairo_set_line_width(cr, 1.5);
  for (double x : {bx + 20.0, bx + 20.0 + len})
    line(cr, x, by + box_h - 22.0, x, by + box_h - 10.0);
  cairo_stroke(cr);
  const std::string label = metres >= 1000.0 ? tickLabel(metres / 1000.0, metres / 1000.0) + " km"
                                             : tickLabel(metres, metres) + " m";
  text(cr, label, bx + box_w / 2.0, by + box_h - 28.0, 0.5, 1.0, kLabel);
}

std::vector<std::string> writePngAndSvg(const std::string& stem, const DrawFn& draw) {
  std::vector<std::string> written;
  for (const bool png : {true, false}) {
    const std::string bytes = png ? renderPng(draw) : renderSvg(draw);
    const std::string path = stem + (png ? ".png" : ".svg");
    io::writeFileAtomic(path, [&](std::ostream& out) {
      out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    });
    written.push_back(path);
  }
  return written;
}

}  // namespace gvio::eval::canvas
