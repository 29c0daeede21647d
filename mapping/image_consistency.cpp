#include "mapping/image_consistency.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include <opencv2/core.hpp>

#include "odometry/error.hpp"

namespace gvio::mapping {
namespace {

void requireSameSize(const cv::Mat& m, const cv::Mat& ref, int type, const char* name) {
  if (m.size() != ref.size() || m.type() != type) {
    throw InvalidInput(fmt::format("image consistency: {} must be {}x{} of type {}", name, ref.cols,
                                   ref.rows, type));
  }
}

// Depth agreement over the patch grid: the share of agreeing pixels over the cells holding at
// least min_cell_depth_pixels pixels with both depths, and its standard error as a ratio estimator
// over those cells (Cochran 1977, sec. 6.4, cluster sampling):
// se^2 = m / (m - 1) sum_c (a_c - p n_c)^2 / N^2, for m cells of n_c pixels, a_c agreeing.
void scoreDepth(const cv::Mat& rendered_depth, const cv::Mat& stereo_depth, double fb,
                const ImageConsistencyConfig& c, ViewScore& score) {
  const int p = c.patch_px;
  std::vector<std::pair<std::size_t, std::size_t>> cells;  // (agreeing, pixels)
  for (int y0 = 0; y0 + p <= rendered_depth.rows; y0 += p) {
    for (int x0 = 0; x0 + p <= rendered_depth.cols; x0 += p) {
      std::size_t agree = 0, pixels = 0;
      for (int y = y0; y < y0 + p; ++y) {
        const float* r = rendered_depth.ptr<float>(y);
        const float* s = stereo_depth.ptr<float>(y);
        for (int x = x0; x < x0 + p; ++x) {
          if (!(r[x] > 0.0F) || !(s[x] > 0.0F) || !std::isfinite(r[x]) || !std::isfinite(s[x])) {
            continue;
          }
          ++pixels;
          const auto zs = static_cast<double>(s[x]);
          if (std::abs(static_cast<double>(r[x]) - zs) <= depthTolerance(zs, fb, c)) ++agree;
        }
      }
      if (pixels >= static_cast<std::size_t>(c.min_cell_depth_pixels)) {
        cells.emplace_back(agree, pixels);
      }
    }
  }
  std::size_t agree = 0, pixels = 0;
  for (const auto& [a, n] : cells) {
    agree += a;
    pixels += n;
  }
  score.depth_cells = static_cast<int>(cells.size());
  score.depth_pixels = pixels;
  if (score.depth_cells < c.min_depth_cells) return;
  const double share = static_cast<double>(agree) / static_cast<double>(pixels);
  double sum = 0.0;
  for (const auto& [a, n] : cells) {
    const double dev = static_cast<double>(a) - share * static_cast<double>(n);
    sum += dev * dev;
  }
  const auto m = static_cast<double>(cells.size());
  score.depth_agreement = share;
  // Never below a binomial share over m patches (Agresti & Coull 1998, two successes and two
  // failures added): patches that all agree alike, or all disagree, measured on few patches are
  // not known to +-0.
  const double p_adjusted = (share * m + 2.0) / (m + 4.0);
  const double binomial = std::sqrt(p_adjusted * (1.0 - p_adjusted) / m);
  score.depth_se = std::max(std::sqrt(m / (m - 1.0) * sum) / static_cast<double>(pixels), binomial);
}

// The mean of the patch ZNCCs and its standard error (sample spread / sqrt(n)).
void scoreNcc(const std::vector<double>& patch_ncc, const ImageConsistencyConfig& c,
              ViewScore& score) {
  score.patches = static_cast<int>(patch_ncc.size());
  if (score.patches < c.min_patches || score.patches < 2) return;
  double sum = 0.0;
  for (const double z : patch_ncc) sum += z;
  const double n = static_cast<double>(patch_ncc.size());
  const double mean = sum / n;
  double ss = 0.0;
  for (const double z : patch_ncc) ss += (z - mean) * (z - mean);
  score.ncc = mean;
  score.ncc_se = std::sqrt(ss / (n - 1.0) / n);
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
  if (min_cell_depth_pixels < 1) fail("min_cell_depth_pixels must be >= 1");
  if (min_depth_cells < 2) fail("min_depth_cells must be >= 2");
  if (!(flag_sigmas > 0.0) || !std::isfinite(flag_sigmas)) fail("flag_sigmas must be > 0");
  if (!(depth_flag_sigmas > 0.0) || !std::isfinite(depth_flag_sigmas)) {
    fail("depth_flag_sigmas must be > 0");
  }
  if (!(min_flag_sigma > 0.0) || !std::isfinite(min_flag_sigma)) {
    fail("min_flag_sigma must be > 0");
  }
  if (min_views_to_flag < 3) fail("min_views_to_flag must be >= 3");
  if (similar_views != 0 && similar_views < min_views_to_flag) {
    fail("similar_views must be 0 (off) or >= min_views_to_flag");
  }
  if (!(min_ncc >= -1.0 && min_ncc <= 1.0)) fail("min_ncc must be in [-1, 1]");
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
  std::vector<double> patch_ncc;
  for (int y = 0; y + p <= recorded.rows; y += p) {
    for (int x = 0; x + p <= recorded.cols; x += p) {
      const cv::Rect r(x, y, p, p);
      const cv::Mat mask = covered(r);
      if (cv::countNonZero(mask) < min_covered) continue;
      const double z = maskedZncc(recorded(r), rendered(r), mask, c.min_patch_stddev);
      if (std::isfinite(z)) patch_ncc.push_back(z);
    }
  }
  scoreNcc(patch_ncc, c, score);
  scoreDepth(rendered_depth_m, stereo_depth_m, focal_baseline_px_m, c, score);
  return score;
}

}  // namespace gvio::mapping
