#include "odometry/vio_estimator.hpp"

#include <opencv2/calib3d.hpp>

#include <chrono>
#include <cmath>
#include <string>
#include <utility>

#include "odometry/error.hpp"
#include "odometry/vio_estimator_impl.hpp"

namespace gvio::odometry {
namespace {

using Clock = std::chrono::steady_clock;
double msSince(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

// A frame further than this after the previous one is a time jump: the state is stale.
constexpr double kTimeJumpS = 1.0;
// A keyframe at least this often bounds the preintegration length (and a standing vehicle).
constexpr double kMaxKeyframeIntervalS = 1.0;
// IMU kept before the oldest frame of a window not yet aligned, for its re-timing (t_d up to this).
constexpr std::int64_t kRetimeImuMarginNs = 200'000'000;

PinholeView viewOf(const CameraModel& cam) {
  PinholeView v;
  v.fx = cam.fx;
  v.fy = cam.fy;
  v.cx = cam.cx;
  v.cy = cam.cy;
  v.T_b_c = cam.T_b_c;
  return v;
}

void requireRectified(const CameraModel& cam) {
  if (!(cam.fx > 0 && cam.fy > 0 && cam.width_px > 0 && cam.height_px > 0)) {
    throw InvalidInput("vio: camera '" + cam.name + "' has invalid intrinsics or size");
  }
  if (hasLensDistortion(cam)) {  // equidistant cameras included, whatever their coefficients
    throw InvalidInput("vio: camera '" + cam.name +
                       "' has lens distortion; the estimator needs rectified cameras");
  }
}

StereoGeometry makeGeometry(const EstimatorConfig& config, const CameraModel& left,
                            const std::optional<CameraModel>& right) {
  requireRectified(left);
  StereoGeometry g;
  g.left = viewOf(left);
  if (!usesStereo(config.mode)) return g;
  if (!right) throw InvalidInput("vio: mode " + toString(config.mode) + " needs a right camera");
  requireRectified(*right);
  const Eigen::Isometry3d T_l_r = left.T_b_c.inverse() * right->T_b_c;
  const bool same_k = std::abs(left.fx - right->fx) < 1e-6 &&
                      std::abs(left.fy - right->fy) < 1e-6 &&
                      std::abs(left.cx - right->cx) < 1e-6 && std::abs(left.cy - right->cy) < 1e-6;
  const Eigen::Vector3d t = T_l_r.translation();
  const bool rectified = (T_l_r.rotation() - Eigen::Matrix3d::Identity()).norm() < 1e-6 &&
                         t.x() > 0.0 && std::hypot(t.y(), t.z()) < 1e-6 * t.x();
  if (!same_k || !rectified || left.width_px != right->width_px ||
      left.height_px != right->height_px) {
    throw InvalidInput(
        "vio: the stereo pair is not rectified (equal intrinsics, right camera displaced along "
        "the left x axis only)");
  }
  g.stereo = true;
  g.right = viewOf(*right);
  g.baseline_m = t.x();
  return g;
}

}  // namespace

VioEstimator::Impl::Impl(const EstimatorConfig& c, const StereoGeometry& g)
    : config(c),
      geometry(g),
      tracker([&] {
        TrackerConfig t = c.tracker;
        t.stereo = g.stereo;
        return t;
      }()),
      window(c, g) {}

void VioEstimator::Impl::event(std::int64_t t_ns, const std::string& kind,
                               const std::string& message) {
  events.push_back({t_ns, kind, message});
}

bool VioEstimator::Impl::checkTime(std::int64_t t_ns) {
  if (last_frame_ns >= 0) {
    const std::int64_t dt = t_ns - last_frame_ns;
    if (dt <= 0) {
      event(t_ns, "time_jump", "frame stamp not after the previous frame: frame ignored");
      return false;
    }
    if (nominal_frame_ns == 0 || dt < nominal_frame_ns) nominal_frame_ns = dt;
    if (static_cast<double>(dt) * 1e-9 > kTimeJumpS) {
      restart(t_ns, "time_jump",
              "time jump of " + std::to_string(static_cast<double>(dt) * 1e-9) +
                  " s: restarting the window",
              false);
      previous_pose.reset();  // the old velocity says nothing about the motion after the jump
    } else if (nominal_frame_ns > 0 && dt > nominal_frame_ns * 3 / 2) {
      event(t_ns, "dropped_frame",
            std::to_string(dt / nominal_frame_ns - 1) + " frame(s) missing before this one");
    }
  }
  last_frame_ns = t_ns;
  return true;
}

void VioEstimator::Impl::restart(std::int64_t t_ns, const std::string& kind, const std::string& why,
                                 bool keep_imu_alignment) {
  event(t_ns, kind, why);
  window.clear();
  tracker_reset_pending = true;
  if (!keep_imu_alignment) imu_aligned = false;
  coast_start_ns = -1;
  uncertain_alignment_since_ns = -1;
  alignment_history.clear();
  if (keep_imu_alignment && latest.valid) ++counters.initializations;
}

bool VioEstimator::Impl::isKeyframe(const WindowFrame& f, const TrackedFrame& tracked) const {
  const auto& frames = window.frames();
  if (frames.empty()) return true;
  const WindowFrame& last_kf = *frames.back();
  if (static_cast<double>(f.t_ns - last_kf.t_ns) * 1e-9 >= kMaxKeyframeIntervalS) return true;
  const Parallax parallax = parallaxTo(tracked, last_kf.uid);
  if (parallax.count < config.keyframe_min_tracked) return true;
  // The threshold is an angle (VINS-Mono: MIN_PARALLAX = 10 px / FOCAL_LENGTH), so a pixel means
  // less on a long lens: the rectified left focal length converts it.
  return parallax.mean_px / geometry.left.fx >= config.keyframe_parallax_deg * M_PI / 180.0;
}

VioEstimator::Impl::Parallax VioEstimator::Impl::parallaxTo(const TrackedFrame& tracked,
                                                            std::uint64_t frame_uid) const {
  Parallax p;
  double sum_px = 0.0;
  for (const Feature& feat : tracked.features) {
    auto it = window.landmarks().all().find(feat.id);
    if (it == window.landmarks().all().end()) continue;
    const Observation* o = it->second.in(frame_uid);
    if (o == nullptr) continue;
    ++p.count;
    sum_px += (feat.px_left - o->px_left).norm();
  }
  if (p.count > 0) p.mean_px = sum_px / p.count;
  return p;
}

void VioEstimator::Impl::addObservations(const WindowFrame& f, const TrackedFrame& tracked) {
  for (const Feature& feat : tracked.features) {
    Observation o;
    o.frame_uid = f.uid;
    o.t_ns = f.t_ns;
    o.t_d_base_s = static_cast<double>(f.retime_ns) * 1e-9;
    o.px_left = feat.px_left;
    o.has_right = geometry.stereo && feat.has_right;
    o.px_right = feat.px_right;
    o.velocity_pxps = feat.velocity_pxps;
    o.velocity_right_pxps = feat.velocity_right_pxps;
    if (window.landmarks().observe(feat.id, o)) continue;
    if (f.keyframe) {
      window.landmarks().create(feat.id, o, geometry, config.min_depth_m, config.max_depth_m);
    }
  }
}

void VioEstimator::Impl::anchorWindow(double tilt_sigma_rad) {
  StartPrior start;
  // Vision alone: the first pose is the gauge (all six degrees held). With the IMU aligned, tilt
  // is observable and keeps the uncertainty of its initial estimate.
  start.pose.tilt_rad =
      imuActive() ? std::max(config.init_tilt_sigma_deg * M_PI / 180.0, tilt_sigma_rad) : 1e-4;
  start.speed_bias = imuActive();
  start.velocity_mps = config.init_velocity_sigma_mps;
  start.acc_bias_mps2 = config.acc_bias_prior_mps2;
  start.gyr_bias_radps = config.gyr_bias_prior_radps;
  window.anchorOldest(start);
}

FrameResult VioEstimator::Impl::process(std::int64_t t_ns, const TrackedFrame& tracked) {
  if (static_cast<int>(tracked.features.size()) < config.min_features_tracking) {
    return coast(t_ns, std::to_string(tracked.features.size()) + " features");
  }
  if (coast_start_ns >= 0) {
    event(t_ns, "coasting",
          "tracking recovered after " +
              std::to_string(static_cast<double>(t_ns - coast_start_ns) * 1e-9) + " s");
    coast_start_ns = -1;
  }
  auto frame = predictFrame(t_ns, tracked);
  frame->keyframe = isKeyframe(*frame, tracked);
  addObservations(*frame, tracked);
  window.frames().push_back(std::move(frame));
  WindowFrame& f = *window.frames().back();
  if (window.frames().size() == 1) {
    anchorWindow();
    if (!usesImu(config.mode)) {
      ++counters.initializations;
      event(t_ns, "initialized", "stereo window started (metric depth from the stereo pair)");
    }
  }
  window.landmarks().triangulate(window.poseLookup(), geometry, window.timeOffsetS(),
                                 config.min_depth_m, config.max_depth_m);

  const SolveStats stats = window.solve(imuActive());
  if (stats.time_offset_held) ++counters.time_offset_held_solves;
  if (stats.time_offset_free) ++counters.time_offset_free_solves;
  window.landmarks().rejectOutliers(window.poseLookup(), geometry, window.timeOffsetS(),
                                    config.max_reprojection_px, config.min_depth_m,
                                    config.max_depth_m);
  if (usesImu(config.mode) && !imu_aligned && tryInitialize(t_ns, tracked)) {
    window.solve(true);
  }

  if (latest.valid && (!usesImu(config.mode) || imu_aligned) &&
      !plausibleMotion(latest.T_w_b, f.T_w_b(),
                       static_cast<double>(f.stateNs() - latest.t_ns) * 1e-9)) {
    // Never hand out a jump: drop the frame's solve and go on from the latest estimate.
    window.dropNewest();
    restart(t_ns, "lost", "implausible motion estimate: restarting the window", imuActive());
    return coast(t_ns, "implausible motion estimate");
  }
  FrameResult r;
  r.t_ns = t_ns;
  r.initialized = !usesImu(config.mode) || imu_aligned;
  const LatestState at_stamp = atStamp(f);
  r.T_w_b = at_stamp.T_w_b;
  r.v_w_mps = at_stamp.v_w;
  r.bias = f.bias();
  r.keyframe = f.keyframe;
  r.features = static_cast<int>(tracked.features.size());
  r.landmarks_in_window = stats.landmarks;
  finishFrame(f);
  return r;
}

void VioEstimator::Impl::finishFrame(const WindowFrame& f) {
  if (latest.valid) previous_pose = latest.T_w_b;
  latest = stateOf(f);
  if (f.keyframe) {
    ++counters.keyframes;
    while (window.keyframeCount() > config.window_size) {
      if (keepsAlignmentHistory()) keepForAlignment(*window.frames().front());
      window.marginalizeOldest(imuActive());
    }
  } else {
    window.dropNewest();
  }
  // IMU still needed: from the newest window frame on, and the static-detection interval.
  std::int64_t keep = latest.t_ns - static_cast<std::int64_t>(config.init_window_s * 1e9);
  if (!window.frames().empty()) keep = std::min(keep, window.frames().back()->stateNs());
  // Before the alignment the window may be re-timed (retimeWindow): its IMU is kept, with a margin.
  if (config.estimate_time_offset && !imu_aligned && !window.frames().empty()) {
    keep = std::min(keep, window.frames().front()->stateNs() - kRetimeImuMarginNs);
  }
  // ... and so is that of the frames kept for it (prependHistory).
  if (!imu_aligned && !alignment_history.empty() && !window.frames().empty()) {
    keep = std::min(keep, alignment_history.front().t_ns - window.frames().front()->retime_ns -
                              kRetimeImuMarginNs);
  }
  imu.dropBefore(std::min(keep, latest.t_ns));
}

VioEstimator::VioEstimator(const EstimatorConfig& config, const CameraModel& left,
                           const std::optional<CameraModel>& right) {
  config.validate();
  impl_ = std::make_unique<Impl>(config, makeGeometry(config, left, right));
}

VioEstimator::~VioEstimator() = default;
VioEstimator::VioEstimator(VioEstimator&&) noexcept = default;
VioEstimator& VioEstimator::operator=(VioEstimator&&) noexcept = default;

void VioEstimator::addImu(const ImuSample& sample) {
  if (!usesImu(impl_->config.mode)) return;
  if (!impl_->imu.add(sample)) {
    impl_->event(sample.t_ns, "imu_gap", "IMU sample out of order or not finite: ignored");
  }
}

FrameResult VioEstimator::addFrame(std::int64_t t_ns, const cv::Mat& left, const cv::Mat& right) {
  if (!beginFrame(t_ns)) {
    FrameResult r;
    r.t_ns = t_ns;
    return r;
  }
  const auto start = Clock::now();
  const TrackedFrame tracked = trackFrame(t_ns, left, right);
  return processFrame(t_ns, tracked, msSince(start));
}

bool VioEstimator::beginFrame(std::int64_t t_ns) {
  ++impl_->counters.frames;
  return impl_->checkTime(t_ns);
}

bool VioEstimator::wouldAccept(std::int64_t t_ns) const {
  return impl_->last_frame_ns < 0 || t_ns > impl_->last_frame_ns;
}

TrackedFrame VioEstimator::trackFrame(std::int64_t t_ns, const cv::Mat& left,
                                      const cv::Mat& right) {
  Impl& s = *impl_;
  if (std::exchange(s.tracker_reset_pending, false)) s.tracker.reset();
  return s.tracker.track(t_ns, left, s.geometry.stereo ? right : cv::Mat());
}

VioEstimator::TrackAhead VioEstimator::trackAhead(std::int64_t t_ns, const cv::Mat& left,
                                                  const cv::Mat& right) {
  Impl& s = *impl_;
  TrackAhead ahead;
  ahead.t_ns = t_ns;
  ahead.next_id_before = s.tracker.nextId();
  const auto start = Clock::now();
  ahead.tracked = s.tracker.track(t_ns, left, s.geometry.stereo ? right : cv::Mat());
  ahead.ms_tracking = msSince(start);
  return ahead;
}

TrackedFrame VioEstimator::takeAhead(TrackAhead&& ahead, const cv::Mat& left, const cv::Mat& right,
                                     double& ms_tracking) {
  Impl& s = *impl_;
  if (!std::exchange(s.tracker_reset_pending, false)) {
    ms_tracking = ahead.ms_tracking;
    return std::move(ahead.tracked);
  }
  // A restart came between: the sequential run reset the tracker before this frame. Undo the
  // frame tracked ahead (its new ids included) and track it again after the reset.
  s.tracker.rewind(ahead.next_id_before);
  const auto start = Clock::now();
  TrackedFrame tracked = s.tracker.track(ahead.t_ns, left, s.geometry.stereo ? right : cv::Mat());
  ms_tracking = ahead.ms_tracking + msSince(start);
  return tracked;
}

FrameResult VioEstimator::processFrame(std::int64_t t_ns, const TrackedFrame& tracked,
                                       double ms_tracking) {
  Impl& s = *impl_;
  const auto start_estimator = Clock::now();
  FrameResult r = s.process(t_ns, tracked);
  s.last_features = tracked.features;
  if (tracked.stats.exposure_gain != 1.0) ++s.counters.exposure_corrected_frames;
  if (tracked.stats.stereo_gain != 1.0) ++s.counters.stereo_gain_corrected_frames;
  s.counters.tracked_features += tracked.stats.tracked;
  s.counters.new_features += tracked.stats.new_features;
  s.counters.rejected_forward_backward += tracked.stats.rejected_fb;
  s.counters.rejected_ransac += tracked.stats.rejected_ransac;
  s.counters.stereo_matches += tracked.stats.stereo_matches;
  s.counters.rejected_stereo += tracked.stats.rejected_stereo;
  r.ms_tracking = ms_tracking;
  r.ms_estimator = msSince(start_estimator);
  if (!r.T_w_b.matrix().allFinite() || !r.v_w_mps.allFinite()) {
    // Never hand out NaN: restart and report the frame as not estimated.
    s.restart(t_ns, "reinitialized", "non-finite estimate: window restarted", false);
    s.latest.valid = false;
    r.initialized = false;
  }
  return r;
}

std::vector<VioEvent> VioEstimator::takeEvents() {
  return std::exchange(impl_->events, {});
}

const VioCounters& VioEstimator::counters() const {
  return impl_->counters;
}

double VioEstimator::timeOffsetS() const {
  return impl_->window.timeOffsetS();
}

const std::vector<Feature>& VioEstimator::lastFeatures() const {
  return impl_->last_features;
}

std::vector<LandmarkEstimate> VioEstimator::landmarks() const {
  std::vector<LandmarkEstimate> out;
  const SlidingWindow& w = impl_->window;
  const PoseLookup poses = w.poseLookup();
  for (const auto& [id, lm] : w.landmarks().all()) {
    if (!SlidingWindow::usable(lm)) continue;
    const double* anchor = poses(lm.anchor().frame_uid);
    if (anchor == nullptr) continue;
    LandmarkEstimate e;
    e.id = id;
    e.p_w = LandmarkMap::worldPoint(lm, anchor, w.geometry(), w.timeOffsetS());
    e.observations = static_cast<int>(lm.observations.size());
    e.mean_reprojection_px =
        LandmarkMap::meanReprojectionPx(lm, poses, w.geometry(), w.timeOffsetS());
    out.push_back(e);
  }
  return out;
}

}  // namespace gvio::odometry
