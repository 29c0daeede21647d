// The feature tracker's new corners: Shi-Tomasi corners (Shi and Tomasi 1994, as
// cv::goodFeaturesToTrack finds them) away from the surviving tracks, spread over a grid.
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <numeric>
#include <utility>
#include <vector>

#include "odometry/corner_candidates.hpp"
#include "odometry/feature_tracker.hpp"
#include "odometry/feature_tracker_detail.hpp"

namespace gvio::odometry {
using tracker_detail::compact;
using tracker_detail::gridCell;
using tracker_detail::inside;
namespace {

// Absolute floor on the Shi-Tomasi response (OpenCV's scale for 8-bit images). quality_level is
// relative to the frame's best corner, so on a featureless frame (sky, fog, a covered lens) it
// would turn sensor noise into corners: Gaussian noise of 2 DN peaks at 1.9e-4, while the
// weakest corners kept on textured simulated frames score about 1e-3.
constexpr double kMinCornerResponse = 3e-4;
// Shi-Tomasi gradient covariance over 3x3 blocks of 3x3 Sobel derivatives (goodFeaturesToTrack's
// defaults).
constexpr int kShiTomasiBlock = 3;
constexpr int kShiTomasiAperture = 3;

}  // namespace

// Features that drifted within min_distance of a longer-lived one are dropped (VINS-Fusion's
// setMask): long tracks constrain the window best, and clusters add little information. mask_
// then keeps new corners away from the survivors.
void FeatureTracker::thinOutAndMask(const cv::Size& size) {
  mask_.create(size, CV_8UC1);
  mask_.setTo(cv::Scalar(255));
  std::vector<std::size_t> order(tracks_.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return tracks_[a].length > tracks_[b].length;
  });
  std::vector<bool> keep(tracks_.size(), false);
  for (const std::size_t i : order) {
    const cv::Point p(cvRound(tracks_[i].px.x), cvRound(tracks_[i].px.y));
    if (mask_.at<std::uint8_t>(p) == 0) continue;
    keep[i] = true;
    cv::circle(mask_, p, config_.min_distance_px, cv::Scalar(0), cv::FILLED);
  }
  compact(tracks_, keep);
}

// The candidates of cv::goodFeaturesToTrack: 3x3 local maxima of the minimum eigenvalue inside
// mask_, at least quality_level x the best one (and kMinCornerResponse), strongest first (ties in
// raster order). Computed here rather than by goodFeaturesToTrack because that allocates its
// megabyte-sized response images anew on every call, which cost more than the detection itself.
std::vector<cv::Point2f> FeatureTracker::shiTomasiCorners(const cv::Mat& image) {
  cv::cornerMinEigenVal(image, response_, kShiTomasiBlock, kShiTomasiAperture);
  const int scale = 1 << config_.detect_level;
  const cv::Mat* mask = &mask_;
  if (scale > 1) {
    cv::resize(mask_, detect_mask_, image.size(), 0.0, 0.0, cv::INTER_NEAREST);
    mask = &detect_mask_;
  }
  const auto threshold = static_cast<float>(
      std::max(config_.quality_level * static_cast<double>(maskedMaximum(response_, *mask)),
               kMinCornerResponse));
  // A candidate is a local maximum: no response of its 3 x 3 neighbourhood is larger.
  const std::vector<std::pair<float, int>> candidates =
      localMaximumCandidates(response_, *mask, threshold);
  // pyrDown's pixel (x, y) is centred on (2x, 2y) of the level below.
  std::vector<cv::Point2f> corners(candidates.size());
  for (std::size_t i = 0; i < candidates.size(); ++i) {
    const int index = candidates[i].second;
    corners[i] = cv::Point2f(static_cast<float>(scale * (index % image.cols)),
                             static_cast<float>(scale * (index / image.cols)));
  }
  return corners;
}

// A corner found at detect_level, moved to the strongest full-resolution response within 2^level
// pixels of where that level put it.
cv::Point2f FeatureTracker::refinedCorner(const cv::Mat& left, const cv::Point& pixel) {
  const int r = 1 << config_.detect_level;
  const cv::Rect around =
      cv::Rect(pixel.x - r, pixel.y - r, 2 * r + 1, 2 * r + 1) & cv::Rect(cv::Point(), left.size());
  // An ROI: the filters read the image around it, so the values are the full image's.
  cv::cornerMinEigenVal(left(around), refine_response_, kShiTomasiBlock, kShiTomasiAperture);
  cv::Point best;
  cv::minMaxLoc(refine_response_, nullptr, nullptr, nullptr, &best);
  return {static_cast<float>(around.x + best.x), static_cast<float>(around.y + best.y)};
}

bool FeatureTracker::notOnAnEdge(const cv::Mat& left, const cv::Point2f& corner) {
  if (config_.min_eigen_ratio <= 0.0) return true;
  // The gradients of a 9 x 9 ROI (its filters read the image around it), summed over the 7 x 7
  // inside: the covariance [a b; b d] whose eigenvalues are KLT's conditioning (Shi and Tomasi
  // 1994).
  constexpr int kHalf = 3;
  const cv::Point c(cvRound(corner.x), cvRound(corner.y));
  const cv::Rect roi = cv::Rect(c.x - kHalf - 1, c.y - kHalf - 1, 2 * kHalf + 3, 2 * kHalf + 3) &
                       cv::Rect(cv::Point(), left.size());
  cv::Sobel(left(roi), edge_gx_, CV_32F, 1, 0, 3);
  cv::Sobel(left(roi), edge_gy_, CV_32F, 0, 1, 3);
  double a = 0.0, b = 0.0, d = 0.0;
  for (int y = 1; y + 1 < roi.height; ++y) {
    const float* gx = edge_gx_.ptr<float>(y);
    const float* gy = edge_gy_.ptr<float>(y);
    for (int x = 1; x + 1 < roi.width; ++x) {
      const double u = static_cast<double>(gx[x]), v = static_cast<double>(gy[x]);
      a += u * u;
      b += u * v;
      d += v * v;
    }
  }
  const double half_trace = (a + d) / 2.0;
  const double spread = std::sqrt(std::max(0.0, half_trace * half_trace - (a * d - b * b)));
  const double larger = half_trace + spread, smaller = half_trace - spread;
  return larger > 0.0 && smaller / larger >= config_.min_eigen_ratio;
}

const cv::Mat& FeatureTracker::detectionImage(const cv::Mat& left) {
  const int level = config_.detect_level;
  if (level == 0) return left;
  // buildOpticalFlowPyramid with derivatives: image, derivatives, image, ... per level.
  const auto at = static_cast<std::size_t>(2 * level);
  if (at < left_pyr_.size()) return left_pyr_[at];
  cv::pyrDown(left, detect_image_);
  for (int l = 1; l < level; ++l) cv::pyrDown(detect_image_, detect_image_);
  return detect_image_;
}

// New corners, strongest first, where mask_ allows and their grid cell holds fewer than
// ceil(max_features / cells) features; each one accepted blocks min_distance around itself.
void FeatureTracker::detectNew(const cv::Mat& left, TrackerStats& stats) {
  thinOutAndMask(left.size());
  const int need = config_.max_features - static_cast<int>(tracks_.size());
  if (need <= 0) return;
  const int cells = config_.grid_cols * config_.grid_rows;
  const int cap = (config_.max_features + cells - 1) / cells;
  auto cellOf = [&](const cv::Point2f& p) {
    return static_cast<std::size_t>(gridCell(p, left.size(), config_.grid_cols, config_.grid_rows));
  };
  std::vector<int> count(static_cast<std::size_t>(cells), 0);
  for (const Track& t : tracks_) ++count[cellOf(t.px)];
  int added = 0;
  for (const cv::Point2f& p : shiTomasiCorners(detectionImage(left))) {
    if (added == need) break;
    int& n = count[cellOf(p)];
    const cv::Point pixel(cvRound(p.x), cvRound(p.y));
    if (n >= cap || !inside(p, left.size()) || mask_.at<std::uint8_t>(pixel) == 0) continue;
    const cv::Point2f at = config_.detect_level > 0 ? refinedCorner(left, pixel) : p;
    if (!notOnAnEdge(left, at)) continue;
    cv::circle(mask_, cv::Point(cvRound(at.x), cvRound(at.y)), config_.min_distance_px,
               cv::Scalar(0), cv::FILLED);
    ++n;
    ++added;
    Track t;
    t.id = next_id_++;
    t.px = at;
    tracks_.push_back(t);
  }
  stats.new_features = added;
}

}  // namespace gvio::odometry
