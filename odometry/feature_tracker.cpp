#include "odometry/feature_tracker.hpp"

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numeric>
#include <string>

#include "odometry/corner_candidates.hpp"
#include "odometry/error.hpp"
#include "odometry/photometric_gain.hpp"

namespace gvio::odometry {
namespace {

// Weight w of the velocity at a frame's stamp, v = step + w (step - previous step), from two
// backward differences over dt and dt_prev (their midpoints (dt + dt_prev) / 2 apart, the newer
// dt / 2 before the stamp): linear extrapolation, exact for a constant image acceleration.
double atStampWeight(double dt_s, double dt_prev_s) {
  return dt_prev_s > 0.0 ? dt_s / (dt_s + dt_prev_s) : 0.0;
}

// Features this close to the image edge are dropped: their KLT window is mostly border padding,
// and a feature about to leave the view is worth nothing to the estimator.
constexpr float kBorderPx = 2.0F;
// KLT stops once an iteration moves the point by less than this (VINS-Fusion's value).
constexpr double kKltEpsilonPx = 0.01;
// findFundamentalMat needs 8 correspondences for its RANSAC model.
constexpr std::size_t kMinRansacPoints = 8;
constexpr double kRansacConfidence = 0.99;
// Absolute floor on the Shi-Tomasi response (OpenCV's scale for 8-bit images). quality_level is
// relative to the frame's best corner, so on a featureless frame (sky, fog, a covered lens) it
// would turn sensor noise into corners: Gaussian noise of 2 DN peaks at 1.9e-4, while the
// weakest corners kept on textured simulated frames score about 1e-3.
constexpr double kMinCornerResponse = 3e-4;
// Shi-Tomasi gradient covariance over 3x3 blocks of 3x3 Sobel derivatives (goodFeaturesToTrack's
// defaults).
constexpr int kShiTomasiBlock = 3;
constexpr int kShiTomasiAperture = 3;
// The reverse KLT pass starts where a correct track must end, so it needs no coarse search: one
// level above full resolution halves its cost (VINS-Fusion does the same), and a wrong forward
// track whose true match lies far away cannot "come back" through the coarse levels. Not none:
// at full resolution alone the check passes more tracks (sparse texture seed 1: 13 instead of 32
// a frame rejected; likely reverse tracks that cannot leave their origin's neighbourhood), and the
// style matrix's sparse texture drives lose (seeds 1-3: 0.100 / 0.088 / 0.076 % of the path with
// one level, 0.178 / 0.105 / 0.227 % with none, 0.126 / 0.104 / 0.075 % with two;
// docs/vio_matrix.md, "Fewer KLT levels").
constexpr int kReverseLevels = 1;

// Half side of the patches whose ZNCC checks a stereo match (11 x 11, the size that separated
// the wrong matches from the correct ones in docs/vio_matrix.md).
constexpr int kZnccHalfPx = 5;
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

// The upper median of a non-empty set (one of its values, never an average of two); reorders it.
float upperMedian(std::vector<float>& values) {
  const auto mid = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), mid, values.end());
  return *mid;
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

bool inside(const cv::Point2f& p, const cv::Size& size) {
  return p.x >= kBorderPx && p.y >= kBorderPx &&
         p.x <= static_cast<float>(size.width - 1) - kBorderPx &&
         p.y <= static_cast<float>(size.height - 1) - kBorderPx;
}

// Row-major index of the grid cell (cols x rows over the image) that holds p.
int gridCell(const cv::Point2f& p, const cv::Size& size, int cols, int rows) {
  const int col = static_cast<int>(p.x * static_cast<float>(cols) / static_cast<float>(size.width));
  const int row =
      static_cast<int>(p.y * static_cast<float>(rows) / static_cast<float>(size.height));
  return std::clamp(row, 0, rows - 1) * cols + std::clamp(col, 0, cols - 1);
}

Eigen::Vector2d toEigen(const cv::Point2f& p) {
  return {static_cast<double>(p.x), static_cast<double>(p.y)};
}

float distance(const cv::Point2f& a, const cv::Point2f& b) {
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
  std::vector<float> err;
  cv::calcOpticalFlowPyrLK(from, to, from_px, to_px, status, err, win, c.klt_levels, term,
                           use_guess ? cv::OPTFLOW_USE_INITIAL_FLOW : 0);
  if (c.klt_refine_window_px > 0) {
    // Full resolution only (level 0 of the same pyramids), from the pyramidal result.
    std::vector<std::uint8_t> refined;
    const cv::Size refine_win(c.klt_refine_window_px, c.klt_refine_window_px);
    cv::calcOpticalFlowPyrLK(from, to, from_px, to_px, refined, err, refine_win, 0, term,
                             cv::OPTFLOW_USE_INITIAL_FLOW);
    for (std::size_t i = 0; i < status.size(); ++i) status[i] = status[i] != 0 && refined[i] != 0;
  }
  // The reverse pass starts at the original position: a correct track comes straight back.
  std::vector<cv::Point2f> back_px = from_px;
  cv::calcOpticalFlowPyrLK(to, from, to_px, back_px, back_status, err, win,
                           std::min(c.klt_levels, kReverseLevels), term,
                           cv::OPTFLOW_USE_INITIAL_FLOW);
  std::vector<bool> ok(from_px.size());
  for (std::size_t i = 0; i < ok.size(); ++i) {
    ok[i] = status[i] != 0 && back_status[i] != 0 &&
            distance(back_px[i], from_px[i]) <= static_cast<float>(c.fb_threshold_px);
  }
  return ok;
}

}  // namespace

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
