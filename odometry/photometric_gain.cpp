#include "odometry/photometric_gain.hpp"

#include <opencv2/core.hpp>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>

namespace gvio::odometry {
namespace {

constexpr int kDarkestUnclipped = 3, kBrightestUnclipped = 250;

// Mean of the (2 half + 1)^2 patch centred on p, bilinear (tracked positions are sub-pixel, and a
// patch half a pixel off on a strong edge changes its mean by more than a small exposure step), or
// none where the patch leaves the image or touches a clipped pixel. The bilinear patch's mean is
// the bilinear blend of the four integer patches' sums around it, from one pass over the
// (2 half + 2)^2 pixels they cover: the mean of cv::getRectSubPix's patch, for a quarter of its
// cost.
std::optional<double> patchMean(const cv::Mat& image, const cv::Point2f& p, int half) {
  const double left = static_cast<double>(p.x) - half, top = static_cast<double>(p.y) - half;
  const int side = 2 * half + 1;
  const auto x0 = static_cast<int>(std::floor(left)), y0 = static_cast<int>(std::floor(top));
  if (!(x0 >= 0 && y0 >= 0 && x0 + side < image.cols && y0 + side < image.rows)) {
    return std::nullopt;
  }
  const double fx = left - x0, fy = top - y0;
  long s00 = 0, s10 = 0, s01 = 0, s11 = 0;  // sums of the patches shifted by (dx, dy)
  int lo = 255, hi = 0;
  for (int r = 0; r <= side; ++r) {
    const std::uint8_t* row = image.ptr<std::uint8_t>(y0 + r) + x0;
    long full = 0;
    for (int c = 0; c <= side; ++c) {
      full += row[c];
      lo = std::min(lo, static_cast<int>(row[c]));
      hi = std::max(hi, static_cast<int>(row[c]));
    }
    const long without_last = full - row[side], without_first = full - row[0];
    if (r < side) {
      s00 += without_last;
      s10 += without_first;
    }
    if (r > 0) {
      s01 += without_last;
      s11 += without_first;
    }
  }
  // A clipped pixel (saturated, or black) does not scale with the gain: such a patch would pull
  // the ratio towards 1.
  if (lo < kDarkestUnclipped || hi > kBrightestUnclipped) return std::nullopt;
  const double sum = (1.0 - fx) * (1.0 - fy) * static_cast<double>(s00) +
                     fx * (1.0 - fy) * static_cast<double>(s10) +
                     (1.0 - fx) * fy * static_cast<double>(s01) +
                     fx * fy * static_cast<double>(s11);
  return sum / static_cast<double>(side * side);
}

}  // namespace

std::optional<double> medianPatchGain(const cv::Mat& from, const cv::Mat& to,
                                      const std::vector<cv::Point2f>& from_px,
                                      const std::vector<cv::Point2f>& to_px,
                                      const std::vector<bool>& matched, int half_px,
                                      int min_points) {
  std::vector<double> ratios;
  ratios.reserve(from_px.size());
  for (std::size_t i = 0; i < from_px.size() && i < to_px.size() && i < matched.size(); ++i) {
    if (!matched[i]) continue;
    const auto a = patchMean(from, from_px[i], half_px);
    const auto b = patchMean(to, to_px[i], half_px);
    // Unclipped patches have means of at least kDarkestUnclipped: the ratio is finite.
    if (a && b) ratios.push_back(*b / *a);
  }
  if (static_cast<int>(ratios.size()) < std::max(min_points, 1)) return std::nullopt;
  // The lower median for an even count: one patch's ratio, not a mean of two.
  const auto mid = ratios.begin() + static_cast<std::ptrdiff_t>((ratios.size() - 1) / 2);
  std::nth_element(ratios.begin(), mid, ratios.end());
  return *mid;
}

std::optional<double> meanImageGain(const cv::Mat& from, const cv::Mat& to) {
  const double from_mean = cv::mean(from)[0];
  if (!(from_mean > 0.0)) return std::nullopt;
  return cv::mean(to)[0] / from_mean;
}

void removeGain(const cv::Mat& image, double gain, cv::Mat& out) {
  image.convertTo(out, CV_8U, 1.0 / gain);
}

}  // namespace gvio::odometry
