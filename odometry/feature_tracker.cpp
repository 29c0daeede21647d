#include "odometry/feature_tracker.hpp"

#include <opencv2/calib3d.hpp>
#include <opencv2/video/tracking.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <string>

#include "odometry/error.hpp"
#include "odometry/feature_tracker_detail.hpp"
#include "odometry/photometric_gain.hpp"

namespace gvio::odometry {
using tracker_detail::atStampWeight;
using tracker_detail::compact;
using tracker_detail::distance;
using tracker_detail::inside;
using tracker_detail::kltForwardBackward;
using tracker_detail::toEigen;
using tracker_detail::upperMedian;
namespace {

// KLT stops once an iteration moves the point by less than this (VINS-Fusion's value).
constexpr double kKltEpsilonPx = 0.01;
// findFundamentalMat needs 8 correspondences for its RANSAC model.
constexpr std::size_t kMinRansacPoints = 8;
constexpr double kRansacConfidence = 0.99;
// The reverse KLT pass starts where a correct track must end, so it needs no coarse search: one
// level above full resolution halves its cost (VINS-Fusion does the same), and a wrong forward
// track whose true match lies far away cannot "come back" through the coarse levels. Not none:
// at full resolution alone the check passes more tracks (sparse texture seed 1: 13 instead of 32
// a frame rejected; likely reverse tracks that cannot leave their origin's neighbourhood), and the
// style matrix's sparse texture drives lose (seeds 1-3: 0.100 / 0.088 / 0.076 % of the path with
// one level, 0.178 / 0.105 / 0.227 % with none, 0.126 / 0.104 / 0.075 % with two;
// docs/benchmarks/vio-matrix.md, "Fewer KLT levels").
constexpr int kReverseLevels = 1;

// Exposure gain: ratios of 9 x 9 patch means (small enough to stay on the tracked surface), and
// at least this many of them, else no correction (a median of a handful says little).
constexpr int kGainPatchHalfPx = 4;
constexpr int kMinGainPoints = 10;
// After the first correction, the gain is measured again until what is left is within this, at
// most kMaxGainPasses times (each pass is one more KLT of every point).
constexpr double kGainTolerance = 0.005;
constexpr int kMaxGainPasses = 3;
// A change beyond this factor is not an exposure step to undo (a covered lens, a frame gone
// black): the points are left as KLT found them.
constexpr double kMaxGainStep = 4.0;

using Clock = std::chrono::steady_clock;

double msSince(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

void requireInt(bool ok, const char* field, int value, const char* rule) {
  if (!ok) {
    throw InvalidInput(std::string("config: tracker.") + field + " must be " + rule + " (got " +
                       std::to_string(value) + ")");
  }
}

void requirePositive(const char* field, double value) {
  if (!std::isfinite(value) || value <= 0.0) {
    throw InvalidInput(std::string("config: tracker.") + field +
                       " must be a positive number (got " + std::to_string(value) + ")");
  }
}

// cv::calcOpticalFlowPyrLK computes a per-point error measure unless told not to (cv::noArray()),
// one more pass over every window at full resolution; nothing here reads it. Computing it is also
// where OpenCV fails a point whose final window starts beyond one window outside the image
// (lkpyramid.cpp, LKTrackerInvoker): the same test, done here, keeps every status as it was.
void markOutOfReach(const std::vector<cv::Point2f>& px, const cv::Size& win, const cv::Size& image,
                    std::vector<std::uint8_t>& status) {
  const cv::Point2f half_win((static_cast<float>(win.width) - 1.0F) * 0.5F,
                             (static_cast<float>(win.height) - 1.0F) * 0.5F);
  for (std::size_t i = 0; i < px.size(); ++i) {
    const cv::Point2f corner = px[i] - half_win;
    const int x = cvFloor(corner.x), y = cvFloor(corner.y);
    if (x < -win.width || x >= image.width || y < -win.height || y >= image.height) status[i] = 0;
  }
}

}  // namespace

namespace tracker_detail {

// Pyramidal KLT from `from` to `to`; `to_px` holds the initial guesses when use_guess. Returns one
// flag per point: found, and the reverse track lands within fb_threshold of where it started.
// Both passes reuse the prebuilt pyramids (with derivatives), so nothing is recomputed.
std::vector<bool> kltForwardBackward(const std::vector<cv::Mat>& from,
                                     const std::vector<cv::Mat>& to,
                                     const std::vector<cv::Point2f>& from_px,
                                     std::vector<cv::Point2f>& to_px, bool use_guess,
                                     const TrackerConfig& c) {
  const cv::Size win(c.klt_window_px, c.klt_window_px);
  const cv::TermCriteria term(cv::TermCriteria::COUNT + cv::TermCriteria::EPS, c.klt_iterations,
                              kKltEpsilonPx);
  std::vector<std::uint8_t> status, back_status;
  cv::calcOpticalFlowPyrLK(from, to, from_px, to_px, status, cv::noArray(), win, c.klt_levels, term,
                           use_guess ? cv::OPTFLOW_USE_INITIAL_FLOW : 0);
  markOutOfReach(to_px, win, to[0].size(), status);
  if (c.klt_refine_window_px > 0) {
    // Full resolution only (level 0 of the same pyramids), from the pyramidal result.
    std::vector<std::uint8_t> refined;
    const cv::Size refine_win(c.klt_refine_window_px, c.klt_refine_window_px);
    cv::calcOpticalFlowPyrLK(from, to, from_px, to_px, refined, cv::noArray(), refine_win, 0, term,
                             cv::OPTFLOW_USE_INITIAL_FLOW);
    markOutOfReach(to_px, refine_win, to[0].size(), refined);
    for (std::size_t i = 0; i < status.size(); ++i) status[i] = status[i] != 0 && refined[i] != 0;
  }
  // The reverse pass starts at the original position: a correct track comes straight back.
  std::vector<cv::Point2f> back_px = from_px;
  cv::calcOpticalFlowPyrLK(to, from, to_px, back_px, back_status, cv::noArray(), win,
                           std::min(c.klt_levels, kReverseLevels), term,
                           cv::OPTFLOW_USE_INITIAL_FLOW);
  markOutOfReach(back_px, win, from[0].size(), back_status);
  std::vector<bool> ok(from_px.size());
  for (std::size_t i = 0; i < ok.size(); ++i) {
    ok[i] = status[i] != 0 && back_status[i] != 0 &&
            distance(back_px[i], from_px[i]) <= static_cast<float>(c.fb_threshold_px);
  }
  return ok;
}

}  // namespace tracker_detail

void TrackerConfig::validate() const {
  requireInt(max_features >= 1, "max_features", max_features, ">= 1");
  if (!(quality_level > 0.0 && quality_level < 1.0)) {
    throw InvalidInput("config: tracker.quality_level must be in (0, 1) (got " +
                       std::to_string(quality_level) + ")");
  }
  requireInt(min_distance_px >= 0, "min_distance_px", min_distance_px, ">= 0");
  requireInt(grid_cols >= 1, "grid_cols", grid_cols, ">= 1");
  requireInt(grid_rows >= 1, "grid_rows", grid_rows, ">= 1");
  requireInt(klt_window_px >= 3 && klt_window_px % 2 == 1, "klt_window_px", klt_window_px,
             "odd and >= 3");
  requireInt(klt_levels >= 0 && klt_levels <= 8, "klt_levels", klt_levels, "in [0, 8]");
  requireInt(detect_level >= 0 && detect_level <= 3, "detect_level", detect_level, "in [0, 3]");
  if (!(min_eigen_ratio >= 0.0 && min_eigen_ratio <= 1.0)) {
    throw InvalidInput("config: tracker.min_eigen_ratio must be in [0, 1] (got " +
                       std::to_string(min_eigen_ratio) + ")");
  }
  requireInt(klt_iterations >= 1, "klt_iterations", klt_iterations, ">= 1");
  requireInt(
      klt_refine_window_px == 0 || (klt_refine_window_px >= 3 && klt_refine_window_px % 2 == 1 &&
                                    klt_refine_window_px <= klt_window_px),
      "klt_refine_window_px", klt_refine_window_px, "0, or odd, >= 3 and <= klt_window_px");
  requirePositive("fb_threshold_px", fb_threshold_px);
  requirePositive("ransac_threshold_px", ransac_threshold_px);
  requirePositive("stereo_max_vertical_px", stereo_max_vertical_px);
  if (!(gain_threshold >= 0.0 && gain_threshold < 1.0)) {
    throw InvalidInput("config: tracker.gain_threshold must be in [0, 1) (got " +
                       std::to_string(gain_threshold) + ")");
  }
  if (!(stereo_min_zncc >= -1.0 && stereo_min_zncc <= 1.0)) {
    throw InvalidInput("config: tracker.stereo_min_zncc must be in [-1, 1] (got " +
                       std::to_string(stereo_min_zncc) + ")");
  }
  if (!(klt_predict_min_px >= 0.0)) {
    throw InvalidInput("config: tracker.klt_predict_min_px must be >= 0 (got " +
                       std::to_string(klt_predict_min_px) + ")");
  }
}

FeatureTracker::FeatureTracker(const TrackerConfig& config) : config_(config) {
  config_.validate();
}

void FeatureTracker::reset() {
  tracks_.clear();
  has_prev_ = false;
  image_size_ = cv::Size();
}

void FeatureTracker::rewind(std::uint64_t next_id) {
  reset();
  next_id_ = next_id;
}

TrackedFrame FeatureTracker::track(std::int64_t t_ns, const cv::Mat& left, const cv::Mat& right) {
  checkImages(left, right);
  image_size_ = left.size();
  TrackedFrame out;
  out.t_ns = t_ns;
  TrackerStats& stats = out.stats;

  auto start = Clock::now();
  buildPyramid(left, left_pyr_);
  dt_s_ = has_prev_ ? 1e-9 * static_cast<double>(t_ns - prev_t_ns_) : 0.0;
  if (has_prev_ && !tracks_.empty()) trackPrevious(dt_s_, stats);
  stats.ms_track = msSince(start);

  start = Clock::now();
  detectNew(left, stats);
  stats.tracked = static_cast<int>(tracks_.size()) - stats.new_features;
  stats.ms_detect = msSince(start);

  start = Clock::now();
  if (config_.stereo) {
    buildPyramid(right, right_pyr_);
    out.features = matchStereo(stats);
  } else {
    for (const Track& t : tracks_) {
      out.features.push_back(Feature{t.id, toEigen(t.px), false, Eigen::Vector2d::Zero(), t.length,
                                     toEigen(t.velocity_pxps), toEigen(t.velocity_pxps)});
    }
  }
  stats.ms_stereo = msSince(start);

  std::swap(prev_pyr_, left_pyr_);  // this frame's pyramid is the next one's "previous"
  has_prev_ = true;
  prev_t_ns_ = t_ns;
  return out;
}

void FeatureTracker::checkImages(const cv::Mat& left, const cv::Mat& right) const {
  if (left.empty() || left.type() != CV_8UC1)
    throw InvalidInput("feature tracker: the left image must be a non-empty 8-bit grey image");
  if (config_.stereo && (right.empty() || right.type() != CV_8UC1))
    throw InvalidInput("feature tracker: the right image must be a non-empty 8-bit grey image");
  if (config_.stereo && right.size() != left.size()) {
    throw InvalidInput("feature tracker: left and right images differ in size (" +
                       std::to_string(left.cols) + "x" + std::to_string(left.rows) + " vs " +
                       std::to_string(right.cols) + "x" + std::to_string(right.rows) + ")");
  }
  // Tracks are pixel positions: they mean nothing in an image of another size.
  if (!image_size_.empty() && left.size() != image_size_) {
    throw InvalidInput("feature tracker: image size changed from " +
                       std::to_string(image_size_.width) + "x" +
                       std::to_string(image_size_.height) + " to " + std::to_string(left.cols) +
                       "x" + std::to_string(left.rows) + " without reset()");
  }
}

void FeatureTracker::buildPyramid(const cv::Mat& image, std::vector<cv::Mat>& pyr) const {
  // With derivatives, so that every KLT pass that starts from this image reuses them; never
  // sharing the caller's pixels, because the pyramid outlives this call (next frame's "previous").
  cv::buildOpticalFlowPyramid(image, pyr, cv::Size(config_.klt_window_px, config_.klt_window_px),
                              config_.klt_levels, true, cv::BORDER_REFLECT_101, cv::BORDER_CONSTANT,
                              false);
}

void FeatureTracker::trackPrevious(double dt_s, TrackerStats& stats) {
  std::vector<cv::Point2f> prev_px(tracks_.size());
  for (std::size_t i = 0; i < tracks_.size(); ++i) prev_px[i] = tracks_[i].px;
  std::vector<cv::Point2f> cur_px = predictedPositions(dt_s);
  const std::vector<cv::Point2f> start_px = cur_px;
  std::vector<bool> ok = kltForwardBackward(prev_pyr_, left_pyr_, prev_px, cur_px, true, config_);
  // An exposure change between the frames: tracked again against the image with it removed.
  stats.exposure_gain = removeExposureGain(prev_pyr_, left_pyr_, prev_px, start_px, cur_px, ok);
  for (std::size_t i = 0; i < ok.size(); ++i) {
    ok[i] = ok[i] && inside(cur_px[i], image_size_);
    Track& t = tracks_[i];
    const cv::Point2f step =
        dt_s > 0.0 ? (cur_px[i] - prev_px[i]) * static_cast<float>(1.0 / dt_s) : cv::Point2f();
    // A backward difference is the velocity half an interval ago; with the one before it (none
    // yet for a new track: step_dt_s 0), the velocity at the stamp to second order.
    t.velocity_pxps =
        step + (step - t.step_velocity_pxps) * static_cast<float>(atStampWeight(dt_s, t.step_dt_s));
    t.step_velocity_pxps = step;
    t.step_dt_s = dt_s;
    t.px = cur_px[i];
    ++t.length;
  }
  const auto before = tracks_.size();
  compact(tracks_, ok);
  compact(prev_px, ok);
  stats.rejected_fb = static_cast<int>(before - tracks_.size());
  rejectOutliersRansac(prev_px, stats);
}

// Where KLT starts each track: shifted by the frame's common image motion, the median of the
// tracks' image velocities (at the previous stamp, over the tracks that have one) times the
// interval, when that shift is at least klt_predict_min_px; else at the old positions. A car's
// turn moves the whole image by tens of pixels a frame (3.8 deg a frame at 10 Hz is 48 px on
// KITTI's camera), near the pyramid's reach, and tracks started at their old position were lost
// or slid into wrong matches: stereo alone on the test suite's block drive tracked half its
// features through the corners and took a 4 deg yaw step (APE 3.16 m; 0.18 m shifted). The common
// motion is what the rotation does to every pixel alike: VINS-Fusion predicts from the IMU's
// rotation instead; this needs no IMU and no camera model. Below the threshold nothing is shifted:
// each track's own velocity (or the common shift on every frame) also tracked the corners but
// drifted the yaw of straight stereo+IMU drives twice as fast (street seed 1: APE 0.078 -> 0.119
// m; the cause was not isolated), so the start is moved only where the old one fails.
std::vector<cv::Point2f> FeatureTracker::predictedPositions(double dt_s) const {
  std::vector<cv::Point2f> start(tracks_.size());
  for (std::size_t i = 0; i < tracks_.size(); ++i) start[i] = tracks_[i].px;
  std::vector<float> vx, vy;
  for (const Track& t : tracks_) {
    if (t.step_dt_s <= 0.0) continue;
    vx.push_back(t.velocity_pxps.x);
    vy.push_back(t.velocity_pxps.y);
  }
  if (vx.empty()) return start;
  const cv::Point2f shift =
      cv::Point2f(upperMedian(vx), upperMedian(vy)) * static_cast<float>(dt_s);
  if (std::hypot(static_cast<double>(shift.x), static_cast<double>(shift.y)) <
      config_.klt_predict_min_px) {
    return start;
  }
  const float max_x = static_cast<float>(image_size_.width - 1);
  const float max_y = static_cast<float>(image_size_.height - 1);
  for (cv::Point2f& p : start) {
    p = cv::Point2f(std::clamp(p.x + shift.x, 0.0F, max_x), std::clamp(p.y + shift.y, 0.0F, max_y));
  }
  return start;
}

// KLT follows appearance, not geometry: a track that slid along an edge or jumped to a similar
// patch still passes the forward-backward check but breaks the epipolar constraint.
void FeatureTracker::rejectOutliersRansac(const std::vector<cv::Point2f>& prev_px,
                                          TrackerStats& stats) {
  if (tracks_.size() < kMinRansacPoints) return;
  std::vector<cv::Point2f> cur_px(tracks_.size());
  for (std::size_t i = 0; i < tracks_.size(); ++i) cur_px[i] = tracks_[i].px;
  std::vector<std::uint8_t> inlier;
  const cv::Mat F = cv::findFundamentalMat(prev_px, cur_px, cv::FM_RANSAC,
                                           config_.ransac_threshold_px, kRansacConfidence, inlier);
  // No model (degenerate configuration): keeping the tracks is safer than dropping all of them.
  if (F.empty() || inlier.size() != tracks_.size()) return;
  std::vector<bool> keep(inlier.size());
  for (std::size_t i = 0; i < keep.size(); ++i) keep[i] = inlier[i] != 0;
  const auto before = tracks_.size();
  compact(tracks_, keep);
  stats.rejected_ransac = static_cast<int>(before - tracks_.size());
}

// KLT takes part of a brightness change for motion: it slides each patch to where the brightness
// matches better (towards darker surroundings in a brighter image), so a gain measured at the
// first pass's positions falls short of the true one (a 15 % step measured as 10-11 % on the
// tracker tests' drive). The gain is therefore measured again against the corrected image and
// the points tracked again, until what is left is within kGainTolerance.
double FeatureTracker::removeExposureGain(const std::vector<cv::Mat>& from,
                                          const std::vector<cv::Mat>& to,
                                          const std::vector<cv::Point2f>& from_px,
                                          const std::vector<cv::Point2f>& start_px,
                                          std::vector<cv::Point2f>& to_px, std::vector<bool>& ok) {
  double gain = 1.0;
  if (config_.gain_threshold <= 0.0) return gain;
  const std::vector<cv::Mat>* target = &to;
  for (int pass = 0; pass < kMaxGainPasses; ++pass) {
    std::optional<double> step = medianPatchGain(from[0], (*target)[0], from_px, to_px, ok,
                                                 kGainPatchHalfPx, kMinGainPoints);
    // Too few matches to measure it on: the whole images' ratio (a 25 % brighter right camera
    // left 2 of 29 stereo matches a frame on the sparse-texture drive).
    if (!step && pass == 0) step = meanImageGain(from[0], to[0]);
    const double tolerance = pass == 0 ? config_.gain_threshold : kGainTolerance;
    if (!step || !(*step >= 1.0 / kMaxGainStep && *step <= kMaxGainStep) ||
        std::abs(*step - 1.0) <= tolerance) {
      break;
    }
    gain *= *step;
    removeGain(to[0], gain, gain_image_);
    buildPyramid(gain_image_, gain_pyr_);
    target = &gain_pyr_;
    to_px = start_px;
    ok = kltForwardBackward(from, gain_pyr_, from_px, to_px, true, config_);
  }
  return gain;
}

}  // namespace gvio::odometry
