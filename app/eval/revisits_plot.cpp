#include "eval/revisits_plot.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numeric>

#include "eval/plot_canvas.hpp"
#include "odometry/error.hpp"

namespace gvio::eval {
namespace {

using namespace canvas;  // the shared drawing primitives (plot_canvas.hpp)

// A long drive can have millions of pairs; beyond this many, an even spread over the pairs ranked
// by error is drawn (the smallest and the largest always among them), which keeps the PNG
// readable and the SVG small without hiding the worst pairs.
constexpr std::size_t kMaxSegments = 20000;
constexpr int kColourBins = 64;

// Indices into `pairs`, ascending by error (ties by index, so the order is deterministic),
// thinned to at most kMaxSegments.
std::vector<std::size_t> segmentsToDraw(const std::vector<RevisitPair>& pairs) {
  std::vector<std::size_t> order(pairs.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return pairs[a].error_m < pairs[b].error_m;
  });
  if (order.size() <= kMaxSegments) return order;
  std::vector<std::size_t> kept;
  kept.reserve(kMaxSegments);
  const std::size_t last = order.size() - 1;
  for (std::size_t k = 0; k < kMaxSegments; ++k)
    kept.push_back(order[k * last / (kMaxSegments - 1)]);
  return kept;
}

// Segments in error order, so the worst are drawn on top; a run of segments in one colour bin is
// stroked as one path (at most kColourBins paths in the SVG).
void drawPairs(cairo_t* cr, const Frame& f, const RevisitPlotData& d,
               const std::vector<RevisitPair>& pairs, const std::vector<std::size_t>& drawn,
               Range err) {
  const auto [a, b] = d.plane;
  const auto bin = [&](std::size_t k) {
    const double e = pairs[drawn[k]].error_m;
    return std::lround((kColourBins - 1) * (err.span() > 0.0 ? (e - err.lo) / err.span() : 0.5));
  };
  cairo_set_line_width(cr, 2.5);
  cairo_set_line_cap(cr, CAIRO_LINE_CAP_ROUND);  // a zero-length segment still shows as a dot
  for (std::size_t k = 0; k < drawn.size();) {
    const long colour = bin(k);
    for (; k < drawn.size() && bin(k) == colour; ++k) {
      const Eigen::Vector3d &p_i = d.p_est[pairs[drawn[k]].i], &p_j = d.p_est[pairs[drawn[k]].j];
      line(cr, f.px(p_i[a]), f.py(p_i[b]), f.px(p_j[a]), f.py(p_j[b]));
    }
    setColour(cr, viridis(static_cast<double>(colour) / (kColourBins - 1)));
    cairo_stroke(cr);
  }
  cairo_set_line_cap(cr, CAIRO_LINE_CAP_BUTT);
}

void drawRevisitsPlot(cairo_t* cr, double width, double height, const RevisitPlotData& d,
                      const RevisitResult& r) {
  const std::vector<std::size_t> drawn = segmentsToDraw(r.pairs);
  std::vector<Eigen::Vector3d> extent = d.p_ref;
  for (const std::size_t k : drawn) {
    extent.push_back(d.p_est[r.pairs[k].i]);
    extent.push_back(d.p_est[r.pairs[k].j]);
  }
  const Frame f = equalAspectFrame(100.0, kFrameTop, width - 100.0 - 190.0,
                                   height - kFrameTop - kFrameBottom, extent, d.plane);
  const double step = stepFor(f.xr, 7);
  const Range err = r.stats ? Range{r.stats->stats.min, r.stats->stats.max} : Range{0.0, 0.0};
  drawTitle(cr, width, d.title);
  std::string pairs_label = "revisit pair (estimated positions)";
  if (drawn.size() < r.pairs.size()) {
    pairs_label += fmt::format(", {} of {} drawn", drawn.size(), r.pairs.size());
  }
  drawLegend(cr, f.x, kLegendY,
             {{"reference", kRefGrey, Swatch::kDashed}, {pairs_label, kInk, Swatch::kGradient}});
  drawGrid(cr, f, step, step);
  cairo_save(cr);
  f.clip(cr);
  drawCurve(cr, f, component(d.p_ref, d.plane[0]), component(d.p_ref, d.plane[1]), kRefGrey, 2.0,
            true);
  drawPairs(cr, f, d, r.pairs, drawn, err);
  cairo_restore(cr);
  if (r.pairs.empty()) {
    setColour(cr, kInk);
    text(cr, "no revisit pairs", f.x + f.w / 2.0, f.y + f.h / 2.0, 0.5, 0.5, 2.0 * kLabel, true);
  }
  static constexpr std::array<const char*, 3> kNames = {"x (m)", "y (m)", "z (m)"};
  drawAxes(cr, f, step, step, kNames[d.plane[0]], kNames[d.plane[1]]);
  drawScaleBar(cr, f, d.p_ref, d.plane);
  drawColourBar(cr, f.x + f.w + 36.0, f.y, f.h, err, "revisit error (m)");
}

void validate(const RevisitPlotData& d, const RevisitResult& r) {
  if (d.p_ref.empty()) throw InvalidInput("revisits plot: no poses to plot");
  if (d.p_est.size() != d.p_ref.size()) {
    throw InvalidInput(fmt::format("revisits plot: {} reference but {} estimated positions",
                                   d.p_ref.size(), d.p_est.size()));
  }
  for (const RevisitPair& p : r.pairs) {
    if (p.i >= d.p_ref.size() || p.j >= d.p_ref.size()) {
      throw InvalidInput(fmt::format("revisits plot: pair ({}, {}) outside the {} poses", p.i, p.j,
                                     d.p_ref.size()));
    }
  }
  const auto [a, b] = d.plane;
  if (a < 0 || a > 2 || b < 0 || b > 2 || a == b)
    throw InvalidInput("revisits plot: plane axes must be two different axes among 0, 1, 2");
}

}  // namespace

std::vector<std::string> writeRevisitsPlot(const RevisitPlotData& data,
                                           const RevisitResult& revisits,
                                           const std::string& prefix) {
  validate(data, revisits);
  return writePngAndSvg(prefix + "_revisits", [&](cairo_t* cr, double width, double height) {
    drawRevisitsPlot(cr, width, height, data, revisits);
  });
}

}  // namespace gvio::eval
