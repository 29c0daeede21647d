#include "mapping/image_consistency.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <string>

#include <opencv2/core.hpp>

#include "mapping/consistency.hpp"
#include "odometry/error.hpp"

namespace gvio::mapping {
namespace {

// 1.4826 MAD is the standard deviation of a normal distribution (Rousseeuw & Croux 1993).
constexpr double kMadToSigma = 1.4826;

void requireSameSize(const cv::Mat& m, const cv::Mat& ref, int type, const char* name) {
  if (m.size() != ref.size() || m.type() != type) {
    throw InvalidInput(fmt::format("image consistency: {} must be {}x{} of type {}", name, ref.cols,
                                   ref.rows, type));
  }
}

// The median (mapping::percentile's), NaN without values.
double median(std::vector<double> v) {
  return v.empty() ? std::numeric_limits<double>::quiet_NaN() : percentile(v, 0.5);
}

std::vector<double> finiteOf(const std::vector<double>& values) {
  std::vector<double> finite;
  for (const double v : values) {
    if (std::isfinite(v)) finite.push_back(v);
  }
  return finite;
}

double robustSigma(const std::vector<double>& values, double m, double floor) {
  std::vector<double> dev;
  dev.reserve(values.size());
  for (const double v : values) dev.push_back(std::abs(v - m));
  return std::max(kMadToSigma * median(dev), floor);
}

// The global and the per-view local thresholds of one score (NaN: not scored).
ScoreThresholds thresholdsOf(const std::vector<double>& values, const std::vector<double>& t_s,
                             double floor, const ImageConsistencyConfig& c) {
  ScoreThresholds out;
  out.global = floor;
  const double inf = std::numeric_limits<double>::infinity();
  out.local.assign(values.size(), -inf);
  const std::vector<double> finite = finiteOf(values);
  out.median = median(finite);
  if (finite.size() < c.min_views_to_flag) return out;
  out.global = std::max(
      floor, out.median - c.flag_sigmas * robustSigma(finite, out.median, c.min_flag_sigma));
  // Local medians over +-window/2 (two pointers: the times ascend), then the residuals' spread.
  std::vector<double> local_median(values.size(), std::numeric_limits<double>::quiet_NaN());
  std::vector<double> residuals;
  std::size_t lo = 0, hi = 0;
  for (std::size_t i = 0; i < values.size(); ++i) {
    while (t_s[lo] < t_s[i] - 0.5 * c.local_window_s) ++lo;
    while (hi < values.size() && t_s[hi] <= t_s[i] + 0.5 * c.local_window_s) ++hi;
    std::vector<double> window;
    for (std::size_t j = lo; j < hi; ++j) {
      if (std::isfinite(values[j])) window.push_back(values[j]);
    }
    if (window.size() < c.min_views_to_flag || !std::isfinite(values[i])) continue;
    local_median[i] = median(window);
    residuals.push_back(values[i] - local_median[i]);
  }
  if (residuals.size() < c.min_views_to_flag) return out;
  const double sigma = robustSigma(residuals, median(residuals), c.min_flag_sigma);
  for (std::size_t i = 0; i < values.size(); ++i) {
    if (std::isfinite(local_median[i])) out.local[i] = local_median[i] - c.flag_sigmas * sigma;
  }
  return out;
}

double depthAgreement(const cv::Mat& rendered_depth, const cv::Mat& stereo_depth, double fb,
                      const ImageConsistencyConfig& c, std::size_t& pixels) {
  std::size_t agree = 0;
  pixels = 0;
  for (int y = 0; y < rendered_depth.rows; ++y) {
    const float* r = rendered_depth.ptr<float>(y);
    const float* s = stereo_depth.ptr<float>(y);
    for (int x = 0; x < rendered_depth.cols; ++x) {
      if (!(r[x] > 0.0F) || !(s[x] > 0.0F) || !std::isfinite(r[x]) || !std::isfinite(s[x])) {
        continue;
      }
      ++pixels;
      const double zs = s[x];
      if (std::abs(static_cast<double>(r[x]) - zs) <= depthTolerance(zs, fb, c)) ++agree;
    }
  }
  if (pixels < static_cast<std::size_t>(c.min_depth_pixels)) {
    return std::numeric_limits<double>::quiet_NaN();
  }
  return static_cast<double>(agree) / static_cast<double>(pixels);
}

}  // namespace

void ImageConsistencyConfig::validate() const {
  const auto fail = [](const std::string& what) {
    throw InvalidInput("image consistency: " + what);
  };
  if (patch_px < 4 || patch_px > 256) fail("patch_px must be in [4, 256]");
  if (!(min_patch_coverage > 0.0 && min_patch_coverage <= 1.0)) {
    fail("min_patch_coverage must be in (0, 1]");
  }
  if (!(min_patch_stddev >= 0.0) || !std::isfinite(min_patch_stddev)) {
    fail("min_patch_stddev must be >= 0");
  }
  if (!(depth_tolerance_m > 0.0) || !std::isfinite(depth_tolerance_m)) {
    fail("depth_tolerance_m must be > 0");
  }
  if (!(disparity_tolerance_px >= 0.0) || !std::isfinite(disparity_tolerance_px)) {
    fail("disparity_tolerance_px must be >= 0");
  }
  if (min_patches < 1) fail("min_patches must be >= 1");
  if (min_depth_pixels < 1) fail("min_depth_pixels must be >= 1");
  if (!(flag_sigmas > 0.0) || !std::isfinite(flag_sigmas)) fail("flag_sigmas must be > 0");
  if (!(min_flag_sigma > 0.0) || !std::isfinite(min_flag_sigma)) {
    fail("min_flag_sigma must be > 0");
  }
  if (min_views_to_flag < 3) fail("min_views_to_flag must be >= 3");
  if (!(min_ncc >= -1.0 && min_ncc <= 1.0)) fail("min_ncc must be in [-1, 1]");
  if (!(min_depth_agreement >= 0.0 && min_depth_agreement <= 1.0)) {
    fail("min_depth_agreement must be in [0, 1]");
  }
  if (!(min_relative_coverage >= 0.0) || !std::isfinite(min_relative_coverage)) {
    fail("min_relative_coverage must be >= 0");
  }
  if (!(local_window_s > 0.0) || !std::isfinite(local_window_s)) {
    fail("local_window_s must be > 0");
  }
}

double depthTolerance(double z_m, double focal_baseline_px_m, const ImageConsistencyConfig& c) {
  // d = fb / z, so a disparity step of tol moves the depth by z^2 tol / fb (to first order).
  const double from_disparity =
      focal_baseline_px_m > 0.0 ? z_m * z_m * c.disparity_tolerance_px / focal_baseline_px_m : 0.0;
  return std::max(c.depth_tolerance_m, from_disparity);
}

double maskedZncc(const cv::Mat& a, const cv::Mat& b, const cv::Mat& mask, double min_stddev) {
  double sa = 0.0, sb = 0.0, saa = 0.0, sbb = 0.0, sab = 0.0;
  std::size_t n = 0;
  for (int y = 0; y < a.rows; ++y) {
    const std::uint8_t* pa = a.ptr<std::uint8_t>(y);
    const std::uint8_t* pb = b.ptr<std::uint8_t>(y);
    const std::uint8_t* pm = mask.ptr<std::uint8_t>(y);
    for (int x = 0; x < a.cols; ++x) {
      if (pm[x] == 0) continue;
      const double va = pa[x], vb = pb[x];
      sa += va;
      sb += vb;
      saa += va * va;
      sbb += vb * vb;
      sab += va * vb;
      ++n;
    }
  }
  if (n < 2) return std::numeric_limits<double>::quiet_NaN();
  const double inv = 1.0 / static_cast<double>(n);
  const double var_a = saa * inv - sa * sa * inv * inv;
  const double var_b = sbb * inv - sb * sb * inv * inv;
  const double min_var = min_stddev * min_stddev;
  if (!(var_a > 0.0) || !(var_b > 0.0) || var_a < min_var || var_b < min_var) {
    return std::numeric_limits<double>::quiet_NaN();
  }
  const double cov = sab * inv - sa * sb * inv * inv;
  return std::clamp(cov / std::sqrt(var_a * var_b), -1.0, 1.0);
}

ViewScore scoreView(const cv::Mat& recorded, const cv::Mat& rendered, const cv::Mat& covered,
                    const cv::Mat& rendered_depth_m, const cv::Mat& stereo_depth_m,
                    double focal_baseline_px_m, const ImageConsistencyConfig& c) {
  if (recorded.empty() || recorded.type() != CV_8UC1) {
    throw InvalidInput("image consistency: the recorded image must be 8-bit grey");
  }
  requireSameSize(rendered, recorded, CV_8UC1, "the rendered image");
  requireSameSize(covered, recorded, CV_8UC1, "the coverage mask");
  requireSameSize(rendered_depth_m, recorded, CV_32FC1, "the rendered depth");
  requireSameSize(stereo_depth_m, recorded, CV_32FC1, "the stereo depth");
  ViewScore score;
  score.coverage =
      static_cast<double>(cv::countNonZero(covered)) / static_cast<double>(recorded.total());
  const int p = c.patch_px;
  const double min_covered = c.min_patch_coverage * p * p;
  double sum = 0.0;
  for (int y = 0; y + p <= recorded.rows; y += p) {
    for (int x = 0; x + p <= recorded.cols; x += p) {
      const cv::Rect r(x, y, p, p);
      const cv::Mat mask = covered(r);
      if (cv::countNonZero(mask) < min_covered) continue;
      const double z = maskedZncc(recorded(r), rendered(r), mask, c.min_patch_stddev);
      if (!std::isfinite(z)) continue;
      sum += z;
      ++score.patches;
    }
  }
  if (score.patches >= c.min_patches) score.ncc = sum / score.patches;
  score.depth_agreement =
      depthAgreement(rendered_depth_m, stereo_depth_m, focal_baseline_px_m, c, score.depth_pixels);
  return score;
}

FlaggedViews flagOutliers(const std::vector<ViewScore>& views, const std::vector<double>& t_s,
                          const ImageConsistencyConfig& c) {
  if (t_s.size() != views.size()) {
    throw InvalidInput("image consistency: one time per view needed");
  }
  if (!std::is_sorted(t_s.begin(), t_s.end())) {
    throw InvalidInput("image consistency: view times must ascend");
  }
  std::vector<double> ncc, depth;
  for (const ViewScore& v : views) {
    ncc.push_back(v.ncc);
    depth.push_back(v.depth_agreement);
  }
  FlaggedViews out;
  out.ncc = thresholdsOf(ncc, t_s, c.min_ncc, c);
  out.depth.median = median(finiteOf(depth));
  out.depth.global = c.min_depth_agreement;  // the floor only (see the config)
  out.depth.local.assign(views.size(), -std::numeric_limits<double>::infinity());
  out.flagged.resize(views.size(), false);
  std::vector<double> coverage;
  for (const ViewScore& v : views) coverage.push_back(v.coverage);
  const double typical_coverage = median(coverage);
  for (std::size_t i = 0; i < views.size(); ++i) {
    const bool comparable = views[i].coverage >= c.min_relative_coverage * typical_coverage;
    const auto below = [&](double v, const ScoreThresholds& th, double floor) {
      if (!std::isfinite(v)) return false;
      return v < floor || (comparable && (v < th.global || v < th.local[i]));
    };
    out.flagged[i] =
        below(ncc[i], out.ncc, c.min_ncc) || below(depth[i], out.depth, c.min_depth_agreement);
  }
  return out;
}

std::vector<ViewStretch> flaggedStretches(const std::vector<bool>& flagged, std::size_t max_gap) {
  std::vector<ViewStretch> out;
  for (std::size_t i = 0; i < flagged.size(); ++i) {
    if (!flagged[i]) continue;
    if (!out.empty() && i - out.back().last <= max_gap + 1) {
      out.back().last = i;
    } else {
      out.push_back({i, i});
    }
  }
  return out;
}

}  // namespace gvio::mapping
