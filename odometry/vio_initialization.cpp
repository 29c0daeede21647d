// Initialisation of the IMU modes: the window first runs on vision alone (stereo depth gives
// metric poses; the oldest pose fixes the gauge), then gravity, velocities and the gyroscope bias
// are found either from a standing start (static IMU and image) or by the visual-inertial
// alignment of vi_alignment.hpp, and the window is rotated into a gravity-aligned world.
#include <cmath>
#include <cstdio>
#include <string>

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

std::string fmt3(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3f", v);
  return buf;
}

}  // namespace

void VioEstimator::Impl::applyAlignment(const Eigen::Matrix3d& R_w_v,
                                        const std::vector<Eigen::Vector3d>& v_v,
                                        const ImuBias& bias) {
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
  // The prior was linearised in the visual frame; the IMU residuals now anchor the window.
  window.clearPrior();
  imu_aligned = true;
  anchorWindow();
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
  const WindowFrame& oldest = *frames.front();
  double motion = 0.0;
  int n = 0;
  for (const Feature& feat : tracked.features) {
    auto it = window.landmarks().all().find(feat.id);
    if (it == window.landmarks().all().end()) continue;
    const Observation* o = it->second.in(oldest.uid);
    if (o == nullptr) continue;
    motion += (feat.px_left - o->px_left).norm();
    ++n;
  }
  if (n < kMinStaticFeatures || motion / n > config.static_pixel_motion_px) return false;

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
  std::vector<AlignmentFrame> af;
  for (std::size_t k = 0; k < frames.size(); ++k) {
    if (k > 0 && !frames[k]->preintegration) return false;
    AlignmentFrame a;
    const Eigen::Isometry3d T = frames[k]->T_w_b();
    a.R_v_b = T.rotation();
    a.p_v_b = T.translation();
    if (k > 0) a.preintegration = frames[k]->preintegration;
    af.push_back(a);
  }
  const auto result = alignVisualInertial(af, false);
  if (!result) {
    if (!waiting_reported) {
      event(t_ns, "waiting", "visual-inertial alignment not yet well conditioned: waiting");
      waiting_reported = true;
    }
    return false;
  }
  ImuBias bias;
  bias.gyr = result->gyr_bias;
  applyAlignment(result->R_w_v, result->v_v, bias);
  event(t_ns, "initialized",
        "visual-inertial alignment over " + std::to_string(frames.size()) +
            " frames: |g| before refinement " + fmt3(result->gravity_norm_before_refinement) +
            " m/s^2, gyro bias " + fmt3(bias.gyr.norm() * 180.0 / M_PI) + " deg/s");
  return true;
}

bool VioEstimator::Impl::tryInitialize(std::int64_t t_ns, const TrackedFrame& tracked) {
  if (window.frames().empty()) return false;
  if (staticInitialize(t_ns, tracked)) return true;
  // A monocular window has no metric structure before the IMU is aligned, so only a standing
  // start initialises it (the alignment would need the visual SfM of VINS-Mono).
  if (!geometry.stereo) {
    if (!waiting_reported) {
      event(t_ns, "waiting", "mono+IMU initialises from a standing start: waiting");
      waiting_reported = true;
    }
    return false;
  }
  return motionInitialize(t_ns);
}

}  // namespace gvio::odometry
