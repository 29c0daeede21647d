#pragma once
// Helpers shared by the feature tracker's translation units (feature_tracker.cpp: tracking over
// time and the configuration; feature_detection.cpp: new corners; feature_stereo.cpp: the right
// image). Not part of the library's interface.

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <vector>

#include "odometry/feature_tracker.hpp"

namespace gvio::odometry::tracker_detail {

// Features this close to the image edge are dropped: their KLT window is mostly border padding,
// and a feature about to leave the view is worth nothing to the estimator.
constexpr float kBorderPx = 2.0F;
inline bool inside(const cv::Point2f& p, const cv::Size& size) {
  return p.x >= kBorderPx && p.y >= kBorderPx &&
         p.x <= static_cast<float>(size.width - 1) - kBorderPx &&
         p.y <= static_cast<float>(size.height - 1) - kBorderPx;
}

// Row-major index of the grid cell (cols x rows over the image) that holds p.
inline int gridCell(const cv::Point2f& p, const cv::Size& size, int cols, int rows) {
  const int col = static_cast<int>(p.x * static_cast<float>(cols) / static_cast<float>(size.width));
  const int row =
      static_cast<int>(p.y * static_cast<float>(rows) / static_cast<float>(size.height));
  return std::clamp(row, 0, rows - 1) * cols + std::clamp(col, 0, cols - 1);
}

inline Eigen::Vector2d toEigen(const cv::Point2f& p) {
  return {static_cast<double>(p.x), static_cast<double>(p.y)};
}

inline float distance(const cv::Point2f& a, const cv::Point2f& b) {
  return std::hypot(a.x - b.x, a.y - b.y);
}

// Keeps the elements of `v` whose flag is set, in order.
template <typename T>
void compact(std::vector<T>& v, const std::vector<bool>& keep) {
  std::size_t n = 0;
  for (std::size_t i = 0; i < v.size(); ++i) {
    if (keep[i]) v[n++] = v[i];
  }
  v.resize(n);
}

// Weight w of the velocity at a frame's stamp, v = step + w (step - previous step), from two
// backward differences over dt and dt_prev (their midpoints (dt + dt_prev) / 2 apart, the newer
// dt / 2 before the stamp): linear extrapolation, exact for a constant image acceleration.
inline double atStampWeight(double dt_s, double dt_prev_s) {
  return dt_prev_s > 0.0 ? dt_s / (dt_s + dt_prev_s) : 0.0;
}

// The upper median of a non-empty set (one of its values, never an average of two); reorders it.
inline float upperMedian(std::vector<float>& values) {
  const auto mid = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), mid, values.end());
  return *mid;
}

// Pyramidal KLT from `from` to `to`; `to_px` holds the initial guesses when use_guess. Returns one
// flag per point: found, and the reverse track lands within fb_threshold of where it started.
std::vector<bool> kltForwardBackward(const std::vector<cv::Mat>& from,
                                     const std::vector<cv::Mat>& to,
                                     const std::vector<cv::Point2f>& from_px,
                                     std::vector<cv::Point2f>& to_px, bool use_guess,
                                     const TrackerConfig& c);

}  // namespace gvio::odometry::tracker_detail
