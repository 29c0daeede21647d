#include "eval/plots.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "eval/plot_canvas.hpp"
#include "odometry/error.hpp"

namespace gvio::eval {
namespace {

using namespace canvas;  // the shared drawing primitives (plot_canvas.hpp)

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

void drawTrajectoryPlot(cairo_t* cr, double width, double height, const PlotData& d) {
  std::vector<Eigen::Vector3d> both = d.p_ref;
  both.insert(both.end(), d.p_est.begin(), d.p_est.end());
  const Frame f = equalAspectFrame(100.0, kFrameTop, width - 100.0 - 190.0,
                                   height - kFrameTop - kFrameBottom, both, d.plane);
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
  drawScaleBar(cr, f, d.p_est, d.plane);
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
  using PlotFn = void (*)(cairo_t*, double, double, const PlotData&);
  static constexpr std::array<std::pair<const char*, PlotFn>, 3> kPlots = {
      {{"_trajectory", drawTrajectoryPlot}, {"_error", drawErrorPlot}, {"_axes", drawAxesPlot}}};
  std::vector<std::string> written;
  for (const auto& plot : kPlots) {
    const PlotFn draw = plot.second;  // a named copy: clang 14 cannot capture a structured binding
    const auto files = canvas::writePngAndSvg(
        prefix + plot.first,
        [&](cairo_t* cr, double width, double height) { draw(cr, width, height, data); });
    written.insert(written.end(), files.begin(), files.end());
  }
  return written;
}

}  // namespace gvio::eval
