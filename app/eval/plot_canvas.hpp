#pragma once
// Drawing primitives shared by the evaluation plots (plots.cpp, revisits_plot.cpp): colours, axis
// ranges and ticks, text, framed axes, legends, the colour bar and scale bar, and writing one
// drawing as PNG and SVG. Internal to app/eval.
#include <cairo.h>

#include <Eigen/Core>
#include <array>
#include <cmath>
#include <functional>
#include <string>
#include <vector>

namespace gvio::eval::canvas {

inline constexpr int kWidth = 1200;
inline constexpr int kHeight = 900;
inline constexpr double kTitleTop = 16.0, kLegendY = 68.0, kFrameTop = 92.0, kFrameBottom = 78.0;
inline constexpr double kTick = 13.0, kLabel = 15.0;  // font sizes (px)

struct Rgb {
  double r, g, b;
};
inline constexpr Rgb kInk{0.15, 0.15, 0.15}, kGrid{0.9, 0.9, 0.9}, kRefGrey{0.5, 0.5, 0.5};
inline constexpr Rgb kBlue{0.12, 0.47, 0.71}, kOrange{1.0, 0.5, 0.05}, kGreen{0.17, 0.63, 0.17};
inline constexpr Rgb kRed{0.84, 0.15, 0.16}, kOutage{0.55, 0.55, 0.55};

// The project's viridis (render/colormap), in this file's double-precision colour type.
Rgb viridis(double u);
void setColour(cairo_t* cr, Rgb c, double alpha = 1.0);
void line(cairo_t* cr, double x0, double y0, double x1, double y1);
// Dashes of `on` px with `off` px gaps; on = 0 for solid lines.
void dash(cairo_t* cr, double on, double off);

struct Range {
  double lo = 0.0, hi = 1.0;
  [[nodiscard]] double span() const { return hi - lo; }
  [[nodiscard]] double mid() const { return 0.5 * (lo + hi); }
};

// Min/max of the finite values (0..0 when there are none).
Range rangeOf(const std::vector<double>& values);
// Widens `r` by `fraction` of its span on each side; a (numerically) empty range becomes
// mid +- degenerate_half so no axis ever has zero extent.
Range padded(Range r, double fraction, double degenerate_half);
// The largest 1, 2 or 5 x 10^k not above `x` (> 0).
double niceFloor(double x);
// Multiples of `step` inside `r` (at most 64).
std::vector<double> ticks(Range r, double step);
// A nice (1, 2 or 5 x 10^k) step giving about `count` intervals over `r`.
double stepFor(Range r, int count);
std::string tickLabel(double v, double step);
std::string formatValue(double v);  // 4 significant digits

// Draws `s` anchored at (x, y): ax/ay = 0, 0.5, 1 for left/centre/right and top/middle/baseline,
// rotated by `angle` about the anchor. Returns the advance width; x = NaN only measures.
double text(cairo_t* cr, const std::string& s, double x, double y, double ax, double ay,
            double size, bool bold = false, double angle = 0.0);
void drawTitle(cairo_t* cr, double width, const std::string& title);

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

void drawGrid(cairo_t* cr, const Frame& f, double xstep, double ystep);
// Frame outline, x ticks (labelled when `xlabel` is non-empty) and y ticks with a rotated label.
void drawAxes(cairo_t* cr, const Frame& f, double xstep, double ystep, const std::string& xlabel,
              const std::string& ylabel);

enum class Swatch { kLine, kDashed, kBand, kGradient };
struct LegendEntry {
  std::string label;
  Rgb colour;
  Swatch swatch;
};
// One row of legend entries starting at (x, y).
void drawLegend(cairo_t* cr, double x, double y, const std::vector<LegendEntry>& entries);

// A polyline of (xs, ys); a single sample is drawn as a dot.
void drawCurve(cairo_t* cr, const Frame& f, const std::vector<double>& xs,
               const std::vector<double>& ys, Rgb colour, double width, bool dashed = false);

// Coordinate `axis` of every point.
std::vector<double> component(const std::vector<Eigen::Vector3d>& p, int axis);
// A frame at (x, y, w, h) showing `points` projected on the `plane` axes, padded and widened so
// that one metre has the same length on both axes.
Frame equalAspectFrame(double x, double y, double w, double h,
                       const std::vector<Eigen::Vector3d>& points, std::array<int, 2> plane);
// Viridis colour bar from err.lo (bottom) to err.hi (top) with ticks and a rotated label.
void drawColourBar(cairo_t* cr, double x, double y, double h, Range err, const std::string& label);
// A 1/2/5 x 10^k metre bar about a fifth of the frame wide, in the corner with the fewest of
// `avoid` (projected on `plane`).
void drawScaleBar(cairo_t* cr, const Frame& f, const std::vector<Eigen::Vector3d>& avoid,
                  std::array<int, 2> plane);

// Draws on a white kWidth x kHeight canvas.
using DrawFn = std::function<void(cairo_t* cr, double width, double height)>;
// Writes STEM.png and STEM.svg atomically; throws io::InputError naming the file when it cannot be
// written. Returns the two paths.
std::vector<std::string> writePngAndSvg(const std::string& stem, const DrawFn& draw);

}  // namespace gvio::eval::canvas
