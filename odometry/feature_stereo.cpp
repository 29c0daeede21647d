// The feature tracker's stereo matches: each track found again in the right image by KLT along
// the rectified rows, checked forward and backward, against the frame's row offset and
// (optionally) by the patches' correlation.
#include <opencv2/imgproc.hpp>

#include <cmath>
#include <vector>

#include "odometry/feature_tracker.hpp"
#include "odometry/feature_tracker_detail.hpp"

namespace gvio::odometry {
using tracker_detail::atStampWeight;
using tracker_detail::inside;
using tracker_detail::kltForwardBackward;
using tracker_detail::toEigen;
using tracker_detail::upperMedian;
namespace {

// Half side of the patches whose ZNCC checks a stereo match (11 x 11, the size that separated
// the wrong matches from the correct ones in docs/benchmarks/vio-matrix.md).
constexpr int kZnccHalfPx = 5;

// Zero-mean normalised cross-correlation of the (2 half + 1)^2 patches of `a` around `pa` and of
// `b` around `pb`, sampled bilinearly (cv::getRectSubPix, border replicated); -1 when either
// patch is uniform (no correlation to speak of: a match on a flat patch is no match).
double patchZncc(const cv::Mat& a, cv::Point2f pa, const cv::Mat& b, cv::Point2f pb, int half,
                 cv::Mat& patch_a, cv::Mat& patch_b) {
  const cv::Size size(2 * half + 1, 2 * half + 1);
  cv::getRectSubPix(a, size, pa, patch_a, CV_32F);
  cv::getRectSubPix(b, size, pb, patch_b, CV_32F);
  const double n = static_cast<double>(size.area());
  const double mean_a = cv::sum(patch_a)[0] / n;
  const double mean_b = cv::sum(patch_b)[0] / n;
  double ab = 0.0, aa = 0.0, bb = 0.0;
  for (int y = 0; y < size.height; ++y) {
    const float* ra = patch_a.ptr<float>(y);
    const float* rb = patch_b.ptr<float>(y);
    for (int x = 0; x < size.width; ++x) {
      const double da = static_cast<double>(ra[x]) - mean_a;
      const double db = static_cast<double>(rb[x]) - mean_b;
      ab += da * db;
      aa += da * da;
      bb += db * db;
    }
  }
  // A patch whose standard deviation is below a tenth of a grey level is flat (sensor noise of
  // 8-bit images is about 1 DN).
  constexpr double kFlatVariance = 0.01;
  if (aa < kFlatVariance * n || bb < kFlatVariance * n) return -1.0;
  return ab / std::sqrt(aa * bb);
}

// Median of right y - left y over the stereo candidates (KLT converged, inside the image,
// disparity not negative); 0 without any.
float medianRowOffset(const std::vector<cv::Point2f>& left_px,
                      const std::vector<cv::Point2f>& right_px,
                      const std::vector<bool>& candidate) {
  std::vector<float> offsets;
  offsets.reserve(left_px.size());
  for (std::size_t i = 0; i < left_px.size(); ++i) {
    if (candidate[i]) offsets.push_back(right_px[i].y - left_px[i].y);
  }
  return offsets.empty() ? 0.0F : upperMedian(offsets);
}

}  // namespace

bool FeatureTracker::similarPatches(const cv::Point2f& left_px, const cv::Point2f& right_px) {
  if (config_.stereo_min_zncc <= -1.0) return true;
  // Level 0 of a pyramid built with derivatives is its first entry (the image itself).
  return patchZncc(left_pyr_[0], left_px, right_pyr_[0], right_px, kZnccHalfPx, zncc_left_,
                   zncc_right_) >= config_.stereo_min_zncc;
}

// Rectified stereo: the match lies on the same row as every other match (up to the rig's
// rectification offset, the frame's median), left of the left position. KLT starts from
// the previous frame's disparity when the feature had one (close points sit far beyond the
// pyramid's reach from a zero guess), else from the same position.
std::vector<Feature> FeatureTracker::matchStereo(TrackerStats& stats) {
  std::vector<Feature> features;
  features.reserve(tracks_.size());
  if (tracks_.empty()) return features;
  std::vector<cv::Point2f> left_px(tracks_.size()), right_px(tracks_.size());
  for (std::size_t i = 0; i < tracks_.size(); ++i) {
    left_px[i] = tracks_[i].px;
    right_px[i] = left_px[i] - cv::Point2f(tracks_[i].has_disparity ? tracks_[i].disparity : 0, 0);
  }
  const std::vector<cv::Point2f> start_px = right_px;
  std::vector<bool> candidate =
      kltForwardBackward(left_pyr_, right_pyr_, left_px, right_px, true, config_);
  // Cameras that expose independently: matched again with the right image's gain removed.
  stats.stereo_gain =
      removeExposureGain(left_pyr_, right_pyr_, left_px, start_px, right_px, candidate);
  for (std::size_t i = 0; i < tracks_.size(); ++i) {
    candidate[i] =
        candidate[i] && inside(right_px[i], image_size_) && right_px[i].x <= left_px[i].x;
  }
  const float row_offset = medianRowOffset(left_px, right_px, candidate);
  stats.stereo_row_offset_px = static_cast<double>(row_offset);
  for (std::size_t i = 0; i < tracks_.size(); ++i) {
    Track& t = tracks_[i];
    const cv::Point2f& l = left_px[i];
    const cv::Point2f& r = right_px[i];
    const bool match =
        candidate[i] &&
        std::abs(r.y - l.y - row_offset) <= static_cast<float>(config_.stereo_max_vertical_px) &&
        similarPatches(l, r);
    Eigen::Vector2d velocity_right = toEigen(t.velocity_pxps);
    if (match && t.has_disparity && t.length > 1 && dt_s_ > 0.0) {
      const double step = static_cast<double>(l.x - r.x - t.disparity) / dt_s_;
      velocity_right.x() -=
          step + (step - t.disparity_rate_pxps) * atStampWeight(dt_s_, t.disparity_rate_dt_s);
      t.disparity_rate_pxps = step;
      t.disparity_rate_dt_s = dt_s_;
    } else {
      t.disparity_rate_dt_s = 0.0;  // no rate in this frame: the next one starts afresh
    }
    t.has_disparity = match;
    t.disparity = match ? l.x - r.x : 0.0F;
    if (match) {
      ++stats.stereo_matches;
    } else {
      ++stats.rejected_stereo;
    }
    features.push_back(Feature{t.id, toEigen(l), match,
                               match ? toEigen(r) : Eigen::Vector2d::Zero().eval(), t.length,
                               toEigen(t.velocity_pxps), velocity_right});
  }
  return features;
}

}  // namespace gvio::odometry
