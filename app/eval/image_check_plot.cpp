#include "eval/image_check_plot.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "eval/plot_canvas.hpp"
#include "odometry/error.hpp"

namespace gvio::eval {
namespace {

using namespace canvas;  // the shared drawing primitives (plot_canvas.hpp)

void shadeStretches(cairo_t* cr, const Frame& f, const ImageCheckPlotData& d) {
  setColour(cr, kRed, 0.15);
  for (const auto& [t0, t1] : d.stretches_s) {
    // A one-keyframe stretch still gets a visible band.
    const double a = std::max(f.px(t0) - 2.0, f.x), b = std::min(f.px(t1) + 2.0, f.x + f.w);
    if (b > a) cairo_rectangle(cr, a, f.y, b - a, f.h);
  }
  cairo_fill(cr);
}

// A curve broken where the values are not finite.
void drawBroken(cairo_t* cr, const Frame& f, const std::vector<double>& t,
                const std::vector<double>& v, Rgb colour, bool dashed) {
  std::vector<double> xs, ys;
  const auto flush = [&] {
    drawCurve(cr, f, xs, ys, colour, 1.5, dashed);
    xs.clear();
    ys.clear();
  };
  for (std::size_t i = 0; i < v.size(); ++i) {
    if (!std::isfinite(v[i])) {
      flush();
      continue;
    }
    xs.push_back(t[i]);
    ys.push_back(v[i]);
  }
  flush();
}

// One panel: the score as a line (broken where it is not scored), flagged keyframes as red dots,
// the per-keyframe threshold dashed.
void drawPanel(cairo_t* cr, const Frame& f, const ImageCheckPlotData& d,
               const std::vector<double>& score, const std::vector<double>& threshold,
               const std::string& label, bool xlabel) {
  const double xstep = stepFor(f.xr, 8), ystep = stepFor(f.yr, 5);
  drawGrid(cr, f, xstep, ystep);
  cairo_save(cr);
  f.clip(cr);
  shadeStretches(cr, f, d);
  drawBroken(cr, f, d.t_s, score, kBlue, false);
  drawBroken(cr, f, d.t_s, threshold, kRed, true);
  setColour(cr, kRed);
  for (std::size_t i = 0; i < score.size(); ++i) {
    if (!d.flagged[i] || !std::isfinite(score[i])) continue;
    cairo_arc(cr, f.px(d.t_s[i]), f.py(score[i]), 3.5, 0.0, 2.0 * M_PI);
    cairo_fill(cr);
  }
  cairo_restore(cr);
  drawAxes(cr, f, xstep, ystep, xlabel ? "time from the start (s)" : "", label);
}

Range scoreRange(const std::vector<double>& score, const std::vector<double>& threshold,
                 double lo_floor) {
  std::vector<double> values = score;
  values.insert(values.end(), threshold.begin(), threshold.end());
  Range r = rangeOf(values);
  r.lo = std::max(std::min(r.lo, 1.0), lo_floor);
  r.hi = 1.0;
  return padded(r, 0.04, 0.05);
}

void draw(cairo_t* cr, double width, double height, const ImageCheckPlotData& d) {
  drawTitle(cr, width, d.title);
  std::size_t flagged = 0;
  for (const bool b : d.flagged) flagged += b ? 1 : 0;
  drawLegend(cr, 100.0, kLegendY,
             {{"score per keyframe", kBlue, Swatch::kLine},
              {"flag threshold", kRed, Swatch::kDashed},
              {fmt::format("flagged keyframes ({}) and stretches", flagged), kRed, Swatch::kBand}});
  Range t = rangeOf(d.t_s);
  t = padded(t, 0.01, 1.0);
  const double gap = 40.0;
  const double h = (height - kFrameTop - kFrameBottom - gap) / 2.0;
  const Frame top{100.0, kFrameTop, width - 140.0, h, t, scoreRange(d.ncc, d.ncc_threshold, -1.0)};
  const Frame bottom{
      100.0, kFrameTop + h + gap, width - 140.0, h, t, scoreRange(d.depth, d.depth_threshold, 0.0)};
  drawPanel(cr, top, d, d.ncc, d.ncc_threshold, "patch ZNCC", false);
  drawPanel(cr, bottom, d, d.depth, d.depth_threshold, "depth agreement (share)", true);
}

}  // namespace

std::vector<std::string> writeImageCheckPlot(const ImageCheckPlotData& data,
                                             const std::string& stem) {
  const std::size_t n = data.t_s.size();
  if (n == 0) throw InvalidInput("image check plot: no keyframe to plot");
  if (data.ncc.size() != n || data.depth.size() != n || data.flagged.size() != n ||
      data.ncc_threshold.size() != n || data.depth_threshold.size() != n) {
    throw InvalidInput("image check plot: the per-keyframe series differ in length");
  }
  return writePngAndSvg(
      stem, [&](cairo_t* cr, double width, double height) { draw(cr, width, height, data); });
}

}  // namespace gvio::eval
