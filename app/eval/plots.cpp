#include "eval/plots.hpp"

#include <cairo-svg.h>
#include <cairo.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <numbers>
#include <stdexcept>

#include "io/atomic_write.hpp"
#include "odometry/error.hpp"
#include "render/colormap.hpp"

namespace gvio::eval {
namespace {

constexpr int kWidth = 1200;
constexpr int kHeight = 900;
constexpr double kTitleTop = 16.0, kLegendY = 68.0, kFrameTop = 92.0, kFrameBottom = 78.0;
constexpr double kTick = 13.0, kLabel = 15.0;  // font sizes (px)

struct Rgb {
  double r, g, b;
};
constexpr Rgb kInk{0.15, 0.15, 0.15}, kGrid{0.9, 0.9, 0.9}, kRefGrey{0.5, 0.5, 0.5};
constexpr Rgb kBlue{0.12, 0.47, 0.71}, kOrange{1.0, 0.5, 0.05}, kGreen{0.17, 0.63, 0.17};
constexpr Rgb kRed{0.84, 0.15, 0.16}, kOutage{0.55, 0.55, 0.55};

// The project's viridis (render/colormap), in this file's double-precision colour type.
Rgb viridis(double u) {
  const render::Rgb c = render::colormap(render::ColorMap::kViridis, std::isfinite(u) ? u : 0.0);
  return {static_cast<double>(c.r), static_cast<double>(c.g), static_cast<double>(c.b)};
}

void setColour(cairo_t* cr, Rgb c, double alpha = 1.0) {
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

struct Range {
  double lo = 0.0, hi = 1.0;
  [[nodiscard]] double span() const { return hi - lo; }
  [[nodiscard]] double mid() const { return 0.5 * (lo + hi); }
};

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

// The 1, 2 or 5 x 10^k step closest to `raw` (> 0).
double niceStep(double raw) {
  const double mag = std::pow(10.0, std::floor(std::log10(raw)));
  const double f = raw / mag;
  return (f < 1.5 ? 1.0 : f < 3.5 ? 2.0 : f < 7.5 ? 5.0 : 10.0) * mag;
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
            double size, bool bold = false, double angle = 0.0) {
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

// A pixel rectangle showing the data ranges xr, yr.
struct Frame {
  double x, y, w, h;
  Range xr, yr;
  [[nodiscard]] double px(double v) const { return x + (v - xr.lo) / xr.span() * w; }
  [[nodiscard]] double py(double v) const { return y + h - (v - yr.lo) / yr.span() * h; }
  // Pixel-snapped, so 1 px lines are crisp.
  [[nodiscard]] double sx(double v) const { return std::round(px(v)) + 0.5; }
  [[nodiscard]] double sy(double v) const { return std::round(py(v)) + 0.5; }
  void clip(cairo_t* cr) const {
    cairo_rectangle(cr, x, y, w, h);
    cairo_clip(cr);
  }
};

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

enum class Swatch { kLine, kDashed, kBand, kGradient };
struct LegendEntry {
  std::string label;
  Rgb colour;
  Swatch swatch;
};

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

// One row of legend entries starting at (x, y).
void drawLegend(cairo_t* cr, double x, double y, const std::vector<LegendEntry>& entries) {
  for (const LegendEntry& e : entries) {
    drawSwatch(cr, x, y, e);
    setColour(cr, kInk);
    x += 36.0 + text(cr, e.label, x + 36.0, y, 0.0, 0.5, kLabel) + 28.0;
  }
}

void shadeOutages(cairo_t* cr, const Frame& f, const std::vector<std::pair<double, double>>& out) {
  setColour(cr, kOutage, 0.3);
  for (const auto& [t0, t1] : out) {
    const double a = std::max(std::min(t0, t1), f.xr.lo), b = std::min(std::max(t0, t1), f.xr.hi);
    if (b > a) cairo_rectangle(cr, f.px(a), f.y, f.px(b) - f.px(a), f.h);
  }
  cairo_fill(cr);
}

bool anyOutageIn(Range t, const std::vector<std::pair<double, double>>& outages) {
  return std::any_of(outages.begin(), outages.end(), [&](const auto& o) {
    return std::max(o.first, o.second) > t.lo && std::min(o.first, o.second) < t.hi;
  });
}

// A polyline of (xs, ys); a single sample is drawn as a dot.
void drawCurve(cairo_t* cr, const Frame& f, const std::vector<double>& xs,
               const std::vector<double>& ys, Rgb colour, double width, bool dashed = false) {
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

// A horizontal line across the frame at value y (dashed when `on` > 0).
void drawHLine(cairo_t* cr, const Frame& f, double y, Rgb colour, double width, double on) {
  setColour(cr, colour);
  cairo_set_line_width(cr, width);
  dash(cr, on, 0.6 * on);
  line(cr, f.x, f.py(y), f.x + f.w, f.py(y));
  cairo_stroke(cr);
  dash(cr, 0.0, 0.0);
}

// ---- trajectory -------------------------------------------------------------------------------

std::vector<double> component(const std::vector<Eigen::Vector3d>& p, int axis) {
  std::vector<double> out;
  out.reserve(p.size());
  for (const Eigen::Vector3d& v : p) out.push_back(v[axis]);
  return out;
}

// Data ranges of both trajectories, padded and widened so that one metre has the same length on
// both axes.
Frame equalAspectFrame(double x, double y, double w, double h, const PlotData& d) {
  std::vector<double> xs = component(d.p_ref, d.plane[0]), ys = component(d.p_ref, d.plane[1]);
  for (const Eigen::Vector3d& p : d.p_est) xs.push_back(p[d.plane[0]]), ys.push_back(p[d.plane[1]]);
  Range xr = rangeOf(xs), yr = rangeOf(ys);
  const double pad = 0.05 * std::max(xr.span(), yr.span());
  xr = padded({xr.lo - pad, xr.hi + pad}, 0.0, 1.0);
  yr = padded({yr.lo - pad, yr.hi + pad}, 0.0, 1.0);
  const double metres_per_px = std::max(xr.span() / w, yr.span() / h);
  xr = {xr.mid() - 0.5 * w * metres_per_px, xr.mid() + 0.5 * w * metres_per_px};
  yr = {yr.mid() - 0.5 * h * metres_per_px, yr.mid() + 0.5 * h * metres_per_px};
  return {x, y, w, h, xr, yr};
}

// Segments coloured by their mean error; runs of segments in the same one of 64 colour bins are
// stroked as one path, which keeps long trajectories' SVGs small.
void drawEstimate(cairo_t* cr, const Frame& f, const PlotData& d, Range err) {
  const auto [a, b] = d.plane;
  auto bin = [&](std::size_t i) {
    const double e = 0.5 * (d.error[i - 1] + d.error[i]);
    return std::lround(63.0 * (err.span() > 0.0 ? (e - err.lo) / err.span() : 0.5));
  };
  cairo_set_line_width(cr, 3.0);
  cairo_set_line_cap(cr, CAIRO_LINE_CAP_ROUND);
  cairo_set_line_join(cr, CAIRO_LINE_JOIN_ROUND);
  for (std::size_t i = 1; i < d.p_est.size();) {
    const long colour = bin(i);
    cairo_move_to(cr, f.px(d.p_est[i - 1][a]), f.py(d.p_est[i - 1][b]));
    for (; i < d.p_est.size() && bin(i) == colour; ++i) {
      cairo_line_to(cr, f.px(d.p_est[i][a]), f.py(d.p_est[i][b]));
    }
    setColour(cr, viridis(static_cast<double>(colour) / 63.0));
    cairo_stroke(cr);
  }
  cairo_set_line_cap(cr, CAIRO_LINE_CAP_BUTT);
}

void drawStartEnd(cairo_t* cr, const Frame& f, const PlotData& d) {
  const auto [a, b] = d.plane;
  const double sx = f.px(d.p_est.front()[a]), sy = f.py(d.p_est.front()[b]);
  const double ex = f.px(d.p_est.back()[a]), ey = f.py(d.p_est.back()[b]);
  cairo_set_line_width(cr, 1.5);
  for (const bool start : {true, false}) {
    if (start) cairo_arc(cr, sx, sy, 7.0, 0.0, 2.0 * std::numbers::pi);
    if (!start) cairo_rectangle(cr, ex - 6.0, ey - 6.0, 12.0, 12.0);
    setColour(cr, start ? kGreen : kRed);
    cairo_fill_preserve(cr);
    setColour(cr, kInk);
    cairo_stroke(cr);
  }
  // Labels on opposite sides, so a closed loop does not print them over each other.
  text(cr, "start", sx - 10.0, sy - 10.0, 1.0, 1.0, kLabel, true);
  text(cr, "end", ex + 10.0, ey + 10.0, 0.0, 0.0, kLabel, true);
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

// A 1/2/5 x 10^k metre bar about a fifth of the plot wide, in the corner with the fewest poses.
void drawScaleBar(cairo_t* cr, const Frame& f, const PlotData& d) {
  const double metres = niceFloor(f.xr.span() / 5.0), len = metres / f.xr.span() * f.w;
  const double box_w = len + 40.0, box_h = 54.0;
  // Candidate boxes: bottom-left, bottom-right, top-left, top-right.
  const double left = f.x + 12.0, right = f.x + f.w - 12.0 - box_w;
  const double bottom = f.y + f.h - 12.0 - box_h, top = f.y + 12.0;
  const std::array<std::array<double, 2>, 4> corners = {
      {{left, bottom}, {right, bottom}, {left, top}, {right, top}}};
  std::array<int, 4> hits{};
  for (const Eigen::Vector3d& p : d.p_est) {
    const double px = f.px(p[d.plane[0]]), py = f.py(p[d.plane[1]]);
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

void drawTrajectoryPlot(cairo_t* cr, double width, double height, const PlotData& d) {
  const Frame f = equalAspectFrame(100.0, kFrameTop, width - 100.0 - 190.0,
                                   height - kFrameTop - kFrameBottom, d);
  const double step = stepFor(f.xr, 7);
  const Range err = rangeOf(d.error);
  drawTitle(cr, width, d.title);
  drawLegend(cr, f.x, kLegendY,
             {{"reference", kRefGrey, Swatch::kDashed}, {"estimate", kInk, Swatch::kGradient}});
  drawGrid(cr, f, step, step);
  cairo_save(cr);
  f.clip(cr);
  drawCurve(cr, f, component(d.p_ref, d.plane[0]), component(d.p_ref, d.plane[1]), kRefGrey, 2.0,
            true);
  drawEstimate(cr, f, d, err);
  cairo_restore(cr);
  static constexpr std::array<const char*, 3> kNames = {"x (m)", "y (m)", "z (m)"};
  drawAxes(cr, f, step, step, kNames[d.plane[0]], kNames[d.plane[1]]);
  drawStartEnd(cr, f, d);
  drawScaleBar(cr, f, d);
  drawColourBar(cr, f.x + f.w + 36.0, f.y, f.h, err, d.error_label);
}

// ---- error vs time ----------------------------------------------------------------------------

void drawErrorPlot(cairo_t* cr, double width, double height, const PlotData& d) {
  const Stats& s = d.stats;
  const Range t = padded(rangeOf(d.t_s), 0.0, 1.0), e = rangeOf(d.error);
  Range yr = padded({std::min(0.0, e.lo), std::max({e.hi, s.rmse, s.mean + s.std})}, 0.05, 1.0);
  if (e.lo >= 0.0) yr.lo = std::max(yr.lo, 0.0);
  const Frame f{100.0, kFrameTop, width - 140.0, height - kFrameTop - kFrameBottom, t, yr};
  const double xstep = stepFor(f.xr, 10), ystep = stepFor(f.yr, 6);
  drawTitle(cr, width, d.title);
  std::vector<LegendEntry> legend = {
      {d.error_label, kBlue, Swatch::kLine},
      {"rmse " + formatValue(s.rmse), kRed, Swatch::kDashed},
      {"mean " + formatValue(s.mean), kOrange, Swatch::kDashed},
      {"median " + formatValue(s.median), kGreen, Swatch::kDashed},
      {"mean \xC2\xB1 std " + formatValue(s.std), kOrange, Swatch::kBand}};
  if (anyOutageIn(t, d.outages_s)) legend.push_back({"GNSS outage", kOutage, Swatch::kBand});
  drawLegend(cr, f.x, kLegendY, legend);
  drawGrid(cr, f, xstep, ystep);
  cairo_save(cr);
  f.clip(cr);
  shadeOutages(cr, f, d.outages_s);
  setColour(cr, kOrange, 0.12);
  cairo_rectangle(cr, f.x, f.py(s.mean + s.std), f.w, f.py(s.mean - s.std) - f.py(s.mean + s.std));
  cairo_fill(cr);
  drawCurve(cr, f, d.t_s, d.error, kBlue, 1.5);
  drawHLine(cr, f, s.median, kGreen, 2.0, 8.0);
  drawHLine(cr, f, s.mean, kOrange, 2.0, 8.0);
  drawHLine(cr, f, s.rmse, kRed, 2.0, 8.0);
  cairo_restore(cr);
  drawAxes(cr, f, xstep, ystep, d.time_label, d.error_label);
}

// ---- per-axis error ---------------------------------------------------------------------------

void drawAxesPlot(cairo_t* cr, double width, double height, const PlotData& d) {
  constexpr double kGap = 26.0;
  const Range t = padded(rangeOf(d.t_s), 0.0, 1.0);
  const double panel_h = (height - kFrameTop - kFrameBottom - 2.0 * kGap) / 3.0;
  const double xstep = stepFor(t, 10);
  static constexpr std::array<Rgb, 3> kColours = {kRed, kGreen, kBlue};
  static constexpr std::array<const char*, 3> kNames = {"x", "y", "z"};
  drawTitle(cr, width, d.title + ": position error per axis (estimate - reference)");
  std::vector<LegendEntry> legend;
  for (int a = 0; a < 3; ++a) legend.push_back({kNames[a], kColours[a], Swatch::kLine});
  if (anyOutageIn(t, d.outages_s)) legend.push_back({"GNSS outage", kOutage, Swatch::kBand});
  drawLegend(cr, 110.0, kLegendY, legend);
  for (int a = 0; a < 3; ++a) {
    std::vector<double> diff;
    for (std::size_t i = 0; i < d.p_est.size(); ++i) diff.push_back(d.p_est[i][a] - d.p_ref[i][a]);
    const Range v = rangeOf(diff);
    const Range yr = padded({std::min(0.0, v.lo), std::max(0.0, v.hi)}, 0.08, 1.0);
    const Frame f{110.0, kFrameTop + a * (panel_h + kGap), width - 150.0, panel_h, t, yr};
    const double ystep = stepFor(f.yr, 4);
    drawGrid(cr, f, xstep, ystep);
    cairo_save(cr);
    f.clip(cr);
    shadeOutages(cr, f, d.outages_s);
    drawHLine(cr, f, 0.0, kInk, 1.0, 0.0);
    drawCurve(cr, f, d.t_s, diff, kColours[a], 1.5);
    cairo_restore(cr);
    drawAxes(cr, f, xstep, ystep, a == 2 ? d.time_label : "",
             std::string(kNames[a]) + " error (m)");
  }
}

// ---- output -----------------------------------------------------------------------------------

using DrawFn = void (*)(cairo_t*, double, double, const PlotData&);
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

void drawOn(cairo_surface_t* surface, DrawFn draw, const PlotData& data) {
  check(cairo_surface_status(surface));
  const std::unique_ptr<cairo_t, decltype(&cairo_destroy)> cr(cairo_create(surface),
                                                              &cairo_destroy);
  cairo_set_source_rgb(cr.get(), 1.0, 1.0, 1.0);
  cairo_paint(cr.get());
  draw(cr.get(), kWidth, kHeight, data);
  check(cairo_status(cr.get()));
}

std::string renderPng(DrawFn draw, const PlotData& data) {
  SurfacePtr surface(cairo_image_surface_create(CAIRO_FORMAT_RGB24, kWidth, kHeight),
                     &cairo_surface_destroy);
  drawOn(surface.get(), draw, data);
  std::string bytes;
  check(cairo_surface_write_to_png_stream(surface.get(), appendToString, &bytes));
  return bytes;
}

std::string renderSvg(DrawFn draw, const PlotData& data) {
  std::string bytes;
  SurfacePtr surface(cairo_svg_surface_create_for_stream(appendToString, &bytes, kWidth, kHeight),
                     &cairo_surface_destroy);
  cairo_svg_surface_set_document_unit(surface.get(), CAIRO_SVG_UNIT_PX);  // 1200x900 px, not pt
  drawOn(surface.get(), draw, data);
  cairo_surface_finish(surface.get());  // flushes the document into `bytes`
  check(cairo_surface_status(surface.get()));
  return bytes;
}

void validate(const PlotData& d) {
  const std::size_t n = d.t_s.size();
  if (n == 0) throw InvalidInput("plots: no poses to plot");
  if (d.p_ref.size() != n || d.p_est.size() != n || d.error.size() != n) {
    throw InvalidInput("plots: inconsistent sizes (t " + std::to_string(n) + ", reference " +
                       std::to_string(d.p_ref.size()) + ", estimate " +
                       std::to_string(d.p_est.size()) + ", error " +
                       std::to_string(d.error.size()) + ")");
  }
  const auto [a, b] = d.plane;
  if (a < 0 || a > 2 || b < 0 || b > 2 || a == b)
    throw InvalidInput("plots: plane axes must be two different axes among 0, 1, 2");
}

}  // namespace

std::array<int, 2> choosePlane(const std::vector<Eigen::Vector3d>& points) {
  if (points.empty()) return {0, 1};
  Eigen::Vector3d lo = points.front(), hi = points.front();
  for (const Eigen::Vector3d& p : points) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
  const Eigen::Vector3d extent = hi - lo;
  std::array<int, 3> axes = {0, 1, 2};
  std::stable_sort(axes.begin(), axes.end(), [&](int i, int j) { return extent[i] > extent[j]; });
  return {std::min(axes[0], axes[1]), std::max(axes[0], axes[1])};
}

std::vector<std::string> writePlots(const PlotData& data, const std::string& prefix) {
  validate(data);
  static constexpr std::array<std::pair<const char*, DrawFn>, 3> kPlots = {
      {{"_trajectory", drawTrajectoryPlot}, {"_error", drawErrorPlot}, {"_axes", drawAxesPlot}}};
  std::vector<std::string> written;
  for (const auto& [suffix, draw] : kPlots) {
    for (const bool png : {true, false}) {
      const std::string bytes = png ? renderPng(draw, data) : renderSvg(draw, data);
      const std::string path = prefix + suffix + (png ? ".png" : ".svg");
      io::writeFileAtomic(path, [&](std::ostream& out) {
        out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
      });
      written.push_back(path);
    }
  }
  return written;
}

}  // namespace gvio::eval
