// Pose prediction for a new frame (IMU propagation, or constant velocity refined by PnP) and IMU
// coasting through frames that cannot be estimated.
#include <algorithm>
#include <string>

#include "odometry/pnp.hpp"
#include "odometry/vio_estimator_impl.hpp"

namespace gvio::odometry {
namespace {

// Coasting on the IMU alone longer than this drifts too far: the window restarts instead.
constexpr double kMaxCoastS = 2.0;
// A car-like platform does not move faster than this between frames, nor turn faster: an
// estimate that does is a failed solve (a wrong PnP or a local minimum), not motion.
constexpr double kMaxSpeedMps = 70.0;
constexpr double kMaxTurnRateRadps = 2.0;
// solvePnPRansac for the visual pose prediction.
constexpr int kMinPnpPoints = 8;
constexpr float kPnpReprojectionPx = 3.0F;

}  // namespace

bool plausibleMotion(const Eigen::Isometry3d& from, const Eigen::Isometry3d& to, double dt_s) {
  const double dt = std::max(dt_s, 0.01);
  const double angle = Eigen::AngleAxisd(from.rotation().transpose() * to.rotation()).angle();
  return (to.translation() - from.translation()).norm() <= kMaxSpeedMps * dt + 0.5 &&
         angle <= kMaxTurnRateRadps * dt + 0.05;
}

FrameResult VioEstimator::Impl::coast(std::int64_t t_ns, const std::string& why) {
  FrameResult r;
  r.t_ns = t_ns;
  ++counters.lost_frames;
  const bool can_coast =
      imuActive() && latest.valid &&
      imu.covers(latest.t_ns, t_ns, static_cast<std::int64_t>(config.max_imu_gap_s * 1e9));
  if (!can_coast) {
    if (!window.frames().empty()) {
      restart(t_ns, "lost", why + ": tracking lost, restarting at the last estimate", imuActive());
    }
    return r;
  }
  if (coast_start_ns < 0) {
    coast_start_ns = t_ns;
    event(t_ns, "coasting", why + ": propagating on the IMU alone");
  }
  auto pre = imu.preintegrate(latest.t_ns, t_ns, latest.bias, config.imu_noise);
  const Eigen::Vector3d g(0, 0, -kGravity_mps2);
  const double dt = pre->deltaT();
  const Eigen::Matrix3d R = latest.T_w_b.rotation();
  previous_pose = latest.T_w_b;
  latest.T_w_b.translation() += latest.v_w * dt + 0.5 * g * dt * dt + R * pre->deltaP();
  latest.v_w += g * dt + R * pre->deltaV();
  latest.T_w_b.linear() = R * pre->deltaR();
  latest.t_ns = t_ns;
  ++counters.coasted_frames;
  if (static_cast<double>(t_ns - coast_start_ns) * 1e-9 > kMaxCoastS) {
    restart(t_ns, "reinitialized", "coasted longer than 2 s: window restarted at the IMU estimate",
            true);
  }
  r.initialized = true;
  r.T_w_b = latest.T_w_b;
  r.v_w_mps = latest.v_w;
  r.bias = latest.bias;
  return r;
}

std::optional<Eigen::Isometry3d> VioEstimator::Impl::predictVisual(const TrackedFrame& tracked,
                                                                   std::int64_t retime_ns) const {
  std::vector<cv::Point3d> object;
  std::vector<cv::Point2d> image;
  const PoseLookup poses = window.poseLookup();
  const double t_d = window.timeOffsetS();
  for (const Feature& f : tracked.features) {
    auto it = window.landmarks().all().find(f.id);
    if (it == window.landmarks().all().end() || !it->second.has_depth) continue;
    const double* anchor = poses(it->second.anchor().frame_uid);
    if (anchor == nullptr) continue;
    const Eigen::Vector3d p_w = LandmarkMap::worldPoint(it->second, anchor, geometry, t_d);
    object.emplace_back(p_w.x(), p_w.y(), p_w.z());
    // At the state's time, the stamp less retime_ns.
    const Eigen::Vector2d px =
        f.px_left + (t_d - static_cast<double>(retime_ns) * 1e-9) * f.velocity_pxps;
    image.emplace_back(px.x(), px.y());
  }
  if (object.size() < static_cast<std::size_t>(kMinPnpPoints) || !latest.valid) return std::nullopt;
  const double guess_dt_s = static_cast<double>(tracked.t_ns - latest.t_ns) * 1e-9;
  // Initial guess: constant velocity from the last two estimates.
  Eigen::Isometry3d guess = latest.T_w_b;
  if (previous_pose) guess = latest.T_w_b * (previous_pose->inverse() * latest.T_w_b);
  const Eigen::Isometry3d T_c_w = (guess * geometry.left.T_b_c).inverse();
  const cv::Matx33d K(geometry.left.fx, 0, geometry.left.cx, 0, geometry.left.fy, geometry.left.cy,
                      0, 0, 1);
  const auto solved = pnpRansac(object, image, K, T_c_w, kPnpReprojectionPx);
  // A minority of inliers means RANSAC may have locked onto a wrong model: keep the guess.
  if (!solved || solved->inliers < kMinPnpPoints ||
      2 * static_cast<std::size_t>(solved->inliers) < object.size()) {
    return guess;
  }
  const Eigen::Isometry3d pnp = solved->T_c_w.inverse() * geometry.left.T_b_c.inverse();
  return plausibleMotion(latest.T_w_b, pnp, guess_dt_s) ? pnp : guess;
}

std::int64_t VioEstimator::Impl::retimeNs(std::int64_t t_ns) const {
  if (!config.estimate_time_offset || !usesImu(config.mode)) return 0;
  std::int64_t r = retimeNsFor(window.timeOffsetS());
  // The states stay in time order whatever t_d does.
  const auto& frames = window.frames();
  if (!frames.empty()) r = std::min(r, t_ns - frames.back()->stateNs() - 1);
  if (latest.valid) r = std::min(r, t_ns - latest.t_ns - 1);
  return std::max<std::int64_t>(r, 0);
}

LatestState VioEstimator::Impl::propagate(const LatestState& from, std::int64_t to_ns) const {
  // IMU propagation of a state (Forster eq. 33).
  auto pre = imu.preintegrate(from.t_ns, to_ns, from.bias, config.imu_noise);
  const Eigen::Vector3d g(0, 0, -kGravity_mps2);
  const double dt = pre->deltaT();
  const Eigen::Matrix3d R = from.T_w_b.rotation();
  LatestState to = from;
  to.t_ns = to_ns;
  to.T_w_b.linear() = R * pre->deltaR();
  to.T_w_b.translation() =
      from.T_w_b.translation() + from.v_w * dt + 0.5 * g * dt * dt + R * pre->deltaP();
  to.v_w = from.v_w + g * dt + R * pre->deltaV();
  return to;
}

LatestState stateOf(const WindowFrame& f) {
  LatestState s;
  s.valid = true;
  s.t_ns = f.stateNs();
  s.T_w_b = f.T_w_b();
  s.v_w = Eigen::Map<const Eigen::Vector3d>(f.speed_bias.data());
  s.bias = f.bias();
  return s;
}

LatestState VioEstimator::Impl::atStamp(const WindowFrame& f) const {
  const LatestState s = stateOf(f);
  const auto max_hold = static_cast<std::int64_t>(config.max_imu_gap_s * 1e9);
  if (f.retime_ns == 0 || !imuActive() || !imu.covers(s.t_ns, f.t_ns, max_hold)) return s;
  return propagate(s, f.t_ns);
}

std::unique_ptr<WindowFrame> VioEstimator::Impl::predictFrame(std::int64_t t_ns,
                                                              const TrackedFrame& tracked) {
  auto f = std::make_unique<WindowFrame>();
  f->uid = next_uid++;
  f->t_ns = t_ns;
  f->retime_ns = retimeNs(t_ns);
  const std::int64_t state_ns = f->stateNs();
  const auto max_hold = static_cast<std::int64_t>(config.max_imu_gap_s * 1e9);
  const auto& frames = window.frames();
  if (usesImu(config.mode) && !frames.empty() &&
      imu.covers(frames.back()->stateNs(), state_ns, max_hold)) {
    const double gap = imu.largestGapS(frames.back()->stateNs(), state_ns);
    if (gap > config.max_imu_gap_s) {
      ++counters.imu_gaps;
      event(t_ns, "imu_gap", "IMU gap of " + std::to_string(gap) + " s bridged by interpolation");
    }
    f->preintegration = imu.preintegrate(frames.back()->stateNs(), state_ns, frames.back()->bias(),
                                         config.imu_noise);
  } else if (usesImu(config.mode) && !frames.empty()) {
    ++counters.imu_gaps;
    event(t_ns, "imu_gap", "no IMU data up to this frame: visual constraints only");
  }

  if (imuActive() && latest.valid && imu.covers(latest.t_ns, state_ns, max_hold)) {
    const LatestState s = propagate(latest, state_ns);
    poseToBlock(s.T_w_b, f->pose.data());
    f->velocity() = s.v_w;
    f->setBias(latest.bias);
    return f;
  }
  Eigen::Isometry3d T = latest.valid ? latest.T_w_b : Eigen::Isometry3d::Identity();
  if (latest.valid) {
    if (auto visual = predictVisual(tracked, f->retime_ns)) T = *visual;
  }
  poseToBlock(T, f->pose.data());
  f->velocity() = latest.valid ? latest.v_w : Eigen::Vector3d::Zero();
  f->setBias(latest.bias);
  return f;
}

}  // namespace gvio::odometry
