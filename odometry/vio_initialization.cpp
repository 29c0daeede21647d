// Initialisation of the IMU modes: the window first runs on vision alone (stereo depth gives
// metric poses; the oldest pose fixes the gauge), then gravity, velocities and the gyroscope bias
// are found either from a standing start (static IMU and image) or by the visual-inertial
// alignment of vi_alignment.hpp, and the window is rotated into a gravity-aligned world. A
// monocular window in motion first needs its structure: the visual SfM of mono_sfm.hpp, then the
// alignment with scale (VINS-Mono, Qin et al. 2018, sec. V-A and V-B).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <string>

#include "odometry/lie.hpp"
#include "odometry/mono_sfm.hpp"
#include "odometry/vi_alignment.hpp"
#include "odometry/vio_estimator_impl.hpp"

namespace gvio::odometry {
namespace {

// The alignment needs a few frames with preintegrated IMU between them.
constexpr std::size_t kMinAlignmentFrames = 4;
// Fewer IMU samples than this over the static window cannot establish that the vehicle stands.
constexpr int kMinStaticSamples = 10;
// Landmarks needed to judge image motion for the static test.
constexpr int kMinStaticFeatures = 10;
// The window's prior on an observed initial t_d: this times the alignment's sigma, at least the
// floor (setInitialTimeOffset).
constexpr double kInitTimeOffsetSigmaFactor = 3.0;
constexpr double kMinInitTimeOffsetSigmaS = 0.001;

std::string fmt3(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3f", v);
  return buf;
}

// What the alignment reports about t_d, when it estimated it (relative to the window's re-timing
// base_s).
std::string timeOffsetText(const std::optional<TimeOffsetPrior>& prior,
                           const AlignmentResult& result, double base_s) {
  if (!prior) return "";
  const double t_d_s = base_s + result.t_d_s;
  if (!result.t_d_observed) {
    return ", time offset not observed by the window (+- " + fmt3(result.t_d_sigma_s * 1e3) +
           " ms): kept at " + fmt3(t_d_s * 1e3) + " ms";
  }
  return ", time offset " + fmt3(t_d_s * 1e3) + " +- " + fmt3(result.t_d_sigma_s * 1e3) + " ms";
}

}  // namespace

void VioEstimator::Impl::moveToStamps(const AlignmentResult& result) {
  // The vision-only window placed each body where it was at the exposure, result.t_d_s (relative
  // to the window's re-timing) before the state time the IMU belongs to: carry it forward by its
  // velocity and rate (first order in t_d).
  if (result.w_b.empty() || result.t_d_s == 0.0) return;
  auto& frames = window.frames();
  for (std::size_t k = 0; k < frames.size() && k < result.w_b.size(); ++k) {
    const Eigen::Isometry3d T = frames[k]->T_w_b();
    Eigen::Isometry3d T_stamp = Eigen::Isometry3d::Identity();
    T_stamp.linear() = normalizeRotation(T.linear() * expSo3(result.w_b[k] * result.t_d_s));
    T_stamp.translation() = T.translation() + result.v_v[k] * result.t_d_s;
    poseToBlock(T_stamp, frames[k]->pose.data());
  }
}

void VioEstimator::Impl::applyAlignment(const Eigen::Matrix3d& R_w_v,
                                        const std::vector<Eigen::Vector3d>& v_v,
                                        const ImuBias& bias, double tilt_sigma_rad) {
  auto& frames = window.frames();
  // Rotate about the oldest frame's position, so that a re-alignment (after a time jump, seeded
  // with the last estimate) keeps the trajectory continuous.
  const Eigen::Vector3d p0 = frames.front()->T_w_b().translation();
  for (std::size_t k = 0; k < frames.size(); ++k) {
    WindowFrame& f = *frames[k];
    const Eigen::Isometry3d T = f.T_w_b();
    Eigen::Isometry3d T_new = Eigen::Isometry3d::Identity();
    T_new.linear() = R_w_v * T.linear();
    T_new.translation() = p0 + R_w_v * (T.translation() - p0);
    poseToBlock(T_new, f.pose.data());
    f.velocity() = R_w_v * v_v[k];
    f.setBias(bias);
    if (f.preintegration) f.preintegration->reintegrate(bias);
  }
  // The prior was linearised in the visual frame; the IMU residuals now anchor the window. The
  // latest estimate is still in the visual frame (and, for mono, at no scale): it is stale.
  window.clearPrior();
  latest.valid = false;
  previous_pose.reset();
  imu_aligned = true;
  alignment_history.clear();
  anchorWindow(tilt_sigma_rad);
  ++counters.initializations;
}

bool VioEstimator::Impl::staticInitialize(std::int64_t t_ns, const TrackedFrame& tracked) {
  const auto& frames = window.frames();
  const std::int64_t span_ns = static_cast<std::int64_t>(config.init_window_s * 1e9);
  const std::int64_t t0 = t_ns - span_ns;
  if (imu.empty() || imu.firstStamp() > t0 || frames.front()->t_ns > t0) return false;
  const ImuStats st = imu.stats(t0, t_ns);
  if (st.samples < kMinStaticSamples || st.gyr_std > config.static_gyr_radps ||
      st.acc_std > config.static_acc_mps2) {
    return false;
  }
  // Image motion against the oldest window frame.
  const Parallax motion = parallaxTo(tracked, frames.front()->uid);
  if (motion.count < kMinStaticFeatures || motion.mean_px > config.static_pixel_motion_px) {
    return false;
  }

  // Standing still, the accelerometer measures -R_w_b^T g: the body's "up" is the mean specific
  // force; the gyroscope's mean is its bias.
  const Eigen::Matrix3d R_v_b = frames.back()->T_w_b().rotation();
  const Eigen::Vector3d g_v = -(R_v_b * st.mean_acc).normalized() * kGravity_mps2;
  ImuBias bias;
  bias.gyr = st.mean_gyr;
  applyAlignment(gravityAlignment(g_v),
                 std::vector<Eigen::Vector3d>(frames.size(), Eigen::Vector3d::Zero()), bias);
  event(t_ns, "initialized",
        "static initialisation: gyro bias " + fmt3(bias.gyr.norm() * 180.0 / M_PI) +
            " deg/s, specific force " + fmt3(st.mean_acc.norm()) + " m/s^2");
  return true;
}

bool VioEstimator::Impl::motionInitialize(std::int64_t t_ns) {
  const auto& frames = window.frames();
  if (frames.size() < kMinAlignmentFrames) return false;
  if (static_cast<double>(frames.back()->t_ns - frames.front()->t_ns) * 1e-9 <
      config.init_window_s) {
    return false;
  }
  std::vector<AlignmentFrame> af = windowAlignmentFrames();
  if (af.empty()) return false;
  std::size_t history = prependHistory(af);
  std::optional<TimeOffsetPrior> t_d_prior;
  auto result = alignRetimed(af, false, t_d_prior, history);
  if (!result) {
    reportWaiting(t_ns, "visual-inertial alignment not yet well conditioned: waiting");
    return false;
  }
  if (!tiltCertainEnough(t_ns, result->tilt_sigma_rad)) return false;
  // The kept frames have served: the window's own frames follow them.
  const auto kept = static_cast<std::ptrdiff_t>(history);
  result->v_v.erase(result->v_v.begin(), result->v_v.begin() + kept);
  if (!result->w_b.empty()) result->w_b.erase(result->w_b.begin(), result->w_b.begin() + kept);
  const std::int64_t first_ns = history > 0
                                    ? alignment_history[alignment_history.size() - history].t_ns
                                    : frames.front()->t_ns;
  ImuBias bias;
  bias.gyr = result->gyr_bias;
  moveToStamps(*result);
  if (t_d_prior) setInitialTimeOffset(*result);
  applyAlignment(result->R_w_v, result->v_v, bias, result->tilt_sigma_rad);
  event(t_ns, "initialized",
        "visual-inertial alignment over " + std::to_string(af.size()) + " frames (" +
            fmt3(static_cast<double>(t_ns - first_ns) * 1e-9) + " s): |g| before refinement " +
            fmt3(result->gravity_norm_before_refinement) + " m/s^2, tilt +- " +
            fmt3(result->tilt_sigma_rad * 180.0 / M_PI) + " deg, gyro bias " +
            fmt3(bias.gyr.norm() * 180.0 / M_PI) + " deg/s" +
            timeOffsetText(t_d_prior, *result, windowRetimeS()));
  return true;
}

bool VioEstimator::Impl::tiltCertainEnough(std::int64_t t_ns, double tilt_sigma_rad) {
  if (tilt_sigma_rad <= config.init_max_tilt_sigma_deg * M_PI / 180.0) return true;
  if (uncertain_alignment_since_ns < 0) uncertain_alignment_since_ns = t_ns;
  const double waited_s = static_cast<double>(t_ns - uncertain_alignment_since_ns) * 1e-9;
  if (waited_s >= config.init_max_wait_s) return true;
  reportWaiting(t_ns, "visual-inertial alignment: gravity direction uncertain (+- " +
                          fmt3(tilt_sigma_rad * 180.0 / M_PI) + " deg): waiting");
  return false;
}

void VioEstimator::Impl::reportWaiting(std::int64_t t_ns, const std::string& why) {
  if (waiting_reported) return;
  event(t_ns, "waiting", why);
  waiting_reported = true;
}

bool VioEstimator::Impl::monoInitialize(std::int64_t t_ns) {
  auto& frames = window.frames();
  const auto n = static_cast<int>(frames.size());
  if (frames.size() < kMinAlignmentFrames ||
      static_cast<double>(frames.back()->t_ns - frames.front()->t_ns) * 1e-9 <
          config.init_window_s) {
    return false;
  }
  for (std::size_t k = 1; k < frames.size(); ++k) {
    if (!frames[k]->preintegration) return false;
  }
  // Feature tracks of the window in normalised coordinates of the left camera.
  std::map<std::uint64_t, int> index;
  for (int k = 0; k < n; ++k) index[frames[static_cast<std::size_t>(k)]->uid] = k;
  std::vector<SfmTrack> tracks;
  for (const auto& [id, lm] : window.landmarks().all()) {
    SfmTrack t;
    t.id = id;
    for (const Observation& o : lm.observations) {
      const auto it = index.find(o.frame_uid);
      if (it != index.end())
        t.observations.emplace_back(it->second, geometry.bearing(o.px_left).head<2>());
    }
    if (t.observations.size() >= 2) tracks.push_back(std::move(t));
  }
  SfmOptions options;
  options.focal_px = geometry.left.fx;
  const auto sfm = solveMonoSfm(tracks, n, options);
  if (!sfm) {
    reportWaiting(t_ns, "mono+IMU: not enough parallax for the visual SfM yet: waiting");
    return false;
  }
  // Body poses: R_v_b = R_v_c R_c_b, p_v_b = s p_v_c + R_v_c t_c_b (the lever arm is metric).
  const Eigen::Isometry3d T_c_b = geometry.left.T_b_c.inverse();
  std::vector<AlignmentFrame> af(frames.size());
  for (std::size_t k = 0; k < frames.size(); ++k) {
    const Eigen::Isometry3d& T_v_c = sfm->T_v_c[k];
    af[k].R_v_b = T_v_c.rotation() * T_c_b.rotation();
    af[k].p_v_b = T_v_c.translation();
    af[k].lever_v = T_v_c.rotation() * T_c_b.translation();
    if (k > 0) af[k].preintegration = frames[k]->preintegration;
  }
  std::optional<TimeOffsetPrior> t_d_prior;
  std::size_t no_history = 0;
  const auto result = alignRetimed(af, true, t_d_prior, no_history);
  if (!result) {
    reportWaiting(t_ns,
                  "mono+IMU: scale not yet observable (SfM solved, alignment waits for "
                  "acceleration): waiting");
    return false;
  }
  const double s = result->scale;
  for (std::size_t k = 0; k < frames.size(); ++k) {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = af[k].R_v_b;
    T.translation() = s * af[k].p_v_b + af[k].lever_v;
    poseToBlock(T, frames[k]->pose.data());
  }
  // Landmark depths in their anchor camera, metric: inv_depth = inv_depth_visual / s.
  for (auto& [id, lm] : window.landmarks().all()) {
    lm.has_depth = false;
    const auto p = sfm->points_v.find(id);
    const auto anchor = index.find(lm.anchor().frame_uid);
    if (p == sfm->points_v.end() || anchor == index.end()) continue;
    const double depth =
        s * (sfm->T_v_c[static_cast<std::size_t>(anchor->second)].inverse() * p->second).z();
    if (depth >= config.min_depth_m && depth <= config.max_depth_m) {
      lm.inv_depth = 1.0 / depth;
      lm.has_depth = true;
    }
  }
  ImuBias bias;
  bias.gyr = result->gyr_bias;
  moveToStamps(*result);
  if (t_d_prior) setInitialTimeOffset(*result);
  applyAlignment(result->R_w_v, result->v_v, bias);
  event(t_ns, "initialized",
        "mono SfM (" + std::to_string(sfm->points_v.size()) + " points, " + fmt3(sfm->rms_px) +
            " px rms) + visual-inertial alignment over " + std::to_string(frames.size()) +
            " frames: scale " + fmt3(s) + " (+-" + fmt3(100.0 * result->scale_rel_sigma) +
            " %), |g| before refinement " + fmt3(result->gravity_norm_before_refinement) +
            " m/s^2" + timeOffsetText(t_d_prior, *result, windowRetimeS()));
  return true;
}

std::optional<AlignmentResult> VioEstimator::Impl::alignRetimed(
    std::vector<AlignmentFrame>& af, bool mono, std::optional<TimeOffsetPrior>& prior,
    std::size_t& history) {
  prior = timeOffsetPrior();
  auto result = alignVisualInertial(af, mono, 0.1, 0.05, prior);
  if (!result || !prior || !result->t_d_observed ||
      !retimeWindow(windowRetimeS() + result->t_d_s)) {
    return result;
  }
  af.erase(af.begin(), af.begin() + static_cast<std::ptrdiff_t>(history));
  const auto& frames = window.frames();
  af.front().preintegration = nullptr;
  for (std::size_t k = 1; k < frames.size(); ++k) af[k].preintegration = frames[k]->preintegration;
  history = prependHistory(af);
  prior = timeOffsetPrior();
  return alignVisualInertial(af, mono, 0.1, 0.05, prior);
}

bool VioEstimator::Impl::retimeWindow(double t_d_s) {
  auto& frames = window.frames();
  const std::int64_t retime = retimeNsFor(t_d_s);
  if (frames.size() < 2 || retime == frames.front()->retime_ns) return false;
  const auto max_hold = static_cast<std::int64_t>(config.max_imu_gap_s * 1e9);
  std::vector<std::shared_ptr<ImuPreintegration>> pre(frames.size());
  for (std::size_t k = 1; k < frames.size(); ++k) {
    const std::int64_t a = frames[k - 1]->t_ns - retime;
    const std::int64_t b = frames[k]->t_ns - retime;
    // A drive whose IMU starts with its first image has none before that exposure: the first
    // measurement is held back over those t_d (as the last is held forward up to a frame).
    const std::int64_t from = k == 1 && !imu.empty() ? std::max(a, imu.firstStamp()) : a;
    if (a >= b || !imu.covers(from, b, max_hold)) return false;
    pre[k] = imu.preintegrate(a, b, frames[k - 1]->bias(), config.imu_noise);
  }
  for (std::size_t k = 0; k < frames.size(); ++k) {
    frames[k]->retime_ns = retime;
    if (k > 0) frames[k]->preintegration = pre[k];
  }
  for (auto& [id, lm] : window.landmarks().all()) {
    for (Observation& o : lm.observations) o.t_d_base_s = static_cast<double>(retime) * 1e-9;
  }
  window.setTimeOffsetS(t_d_s);
  return true;
}

void VioEstimator::Impl::setInitialTimeOffset(const AlignmentResult& result) {
  // What the alignment observed becomes the window's prior instead of the configured 50 ms (its
  // posterior, where it has one). Alone, before retimeWindow, this changed little: the first solves
  // still pulled a 19.1 ms estimate of a 20 ms lag to 14.6 ms (14.4 ms with the 50 ms prior). The
  // fit's sigma is optimistic (the synchronised slalom: -1.19 +- 0.34 ms), hence factor and floor.
  std::optional<double> sigma_s;
  if (result.t_d_observed) {
    sigma_s = std::max(kInitTimeOffsetSigmaFactor * result.t_d_sigma_s, kMinInitTimeOffsetSigmaS);
  }
  window.setTimeOffsetS(windowRetimeS() + result.t_d_s, sigma_s);
}

double VioEstimator::Impl::windowRetimeS() const {
  const auto& frames = window.frames();
  return frames.empty() ? 0.0 : static_cast<double>(frames.front()->retime_ns) * 1e-9;
}

std::optional<TimeOffsetPrior> VioEstimator::Impl::timeOffsetPrior() const {
  if (!config.estimate_time_offset) return std::nullopt;
  // The alignment sees t_d relative to the re-timing, which t_d does not change before it: every
  // frame of the window has the same one (else no estimate; the window's own solve goes on).
  const auto& frames = window.frames();
  for (const auto& f : frames) {
    if (f->retime_ns != frames.front()->retime_ns) return std::nullopt;
  }
  // Around the current value (the calibration's, or the estimate kept through a restart).
  return TimeOffsetPrior{window.timeOffsetS() - windowRetimeS(), config.time_offset_sigma_s};
}

bool VioEstimator::Impl::tryInitialize(std::int64_t t_ns, const TrackedFrame& tracked) {
  if (window.frames().empty()) return false;
  if (staticInitialize(t_ns, tracked)) return true;
  // A monocular window has no metric structure before the IMU is aligned: SfM first.
  if (!geometry.stereo) return monoInitialize(t_ns);
  return motionInitialize(t_ns);
}

}  // namespace gvio::odometry
