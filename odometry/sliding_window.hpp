#pragma once
// The estimator's sliding window: frame states (pose, velocity and biases) at stable addresses,
// the landmarks, the marginalisation prior, and the two operations on them: one Ceres solve of
// reprojection + IMU + prior residuals, and the marginalisation of the oldest keyframe.
#include <ceres/context.h>
#include <ceres/loss_function.h>
#include <array>
#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <optional>
#include <vector>

#include "odometry/imu_preintegration.hpp"
#include "odometry/landmarks.hpp"
#include "odometry/marginalization.hpp"
#include "odometry/pose_manifold.hpp"
#include "odometry/prior_factor.hpp"
#include "odometry/vio_config.hpp"

namespace gvio::odometry {

struct WindowFrame {
  std::uint64_t uid = 0;
  std::int64_t t_ns = 0;  // the image stamp
  // With the time offset estimated, the state (pose, velocity, IMU preintegration) belongs to the
  // exposure as t_d was estimated when the frame came, t_ns - retime_ns (VINS-Fusion's re-timing),
  // and the factors move its pixels by the rest of t_d only: the first-order pixel motion then
  // covers a correction near zero instead of the whole offset. 0 without estimation.
  std::int64_t retime_ns = 0;
  bool keyframe = false;
  std::array<double, 7> pose{0, 0, 0, 1, 0, 0, 0};  // PoseManifold layout
  std::array<double, 9> speed_bias{};               // v_w, b_acc, b_gyr
  // IMU from the previous window frame to this one; null for the first frame, without an IMU, or
  // across an IMU outage.
  std::shared_ptr<ImuPreintegration> preintegration;

  [[nodiscard]] std::int64_t stateNs() const { return t_ns - retime_ns; }
  [[nodiscard]] Eigen::Isometry3d T_w_b() const { return poseFromBlock(pose.data()); }
  [[nodiscard]] Eigen::Map<Eigen::Vector3d> velocity() {
    return Eigen::Map<Eigen::Vector3d>(speed_bias.data());
  }
  [[nodiscard]] ImuBias bias() const;
  void setBias(const ImuBias& b);
};

// Uncertainty of the state a window starts from (the anchor priors on its oldest frame).
struct StartPrior {
  PoseSigmas pose;
  bool speed_bias = false;  // also a prior on velocity and biases (IMU modes)
  double velocity_mps = 1.0;
  double acc_bias_mps2 = 0.1;
  double gyr_bias_radps = 0.01;
};

struct SolveStats {
  int landmarks = 0;
  int residual_blocks = 0;
  int iterations = 0;
  bool converged = false;
  bool time_offset_held = false;  // t_d estimated but held: the window's motion cannot observe it
  bool time_offset_free = false;  // t_d estimated and free in this solve
};

// How far the window's motion is from stationary (constant body-frame angular rate and specific
// force), the motion under which t_d is unobservable (Li and Mourikis, "Online temporal
// calibration for camera-IMU systems: theory and algorithms", IJRR 2014, sec. 4): shifting every
// state in time by dt_d then agrees with the IMU as well as the true states do. Largest deviation
// of an inter-frame interval's mean rate and force from their window means.
struct TimeOffsetExcitation {
  double rate_change_radps = 0.0;
  double force_change_mps2 = 0.0;
};

class SlidingWindow {
 public:
  SlidingWindow(const EstimatorConfig& config, const StereoGeometry& geometry);

  std::deque<std::unique_ptr<WindowFrame>>& frames() { return frames_; }
  [[nodiscard]] const std::deque<std::unique_ptr<WindowFrame>>& frames() const { return frames_; }
  LandmarkMap& landmarks() { return landmarks_; }
  [[nodiscard]] const LandmarkMap& landmarks() const { return landmarks_; }
  [[nodiscard]] const StereoGeometry& geometry() const { return geometry_; }
  [[nodiscard]] PoseLookup poseLookup() const;
  [[nodiscard]] int keyframeCount() const;
  [[nodiscard]] bool hasPrior() const { return prior_ != nullptr; }
  [[nodiscard]] TimeOffsetExcitation timeOffsetExcitation() const;
  // Whether the window's motion is too close to stationary to observe t_d (the config's
  // thresholds): solve() then keeps t_d where it is.
  [[nodiscard]] bool timeOffsetUnobservable() const;

  // One nonlinear least-squares solve. IMU residuals join when `use_imu` (then the speed/bias
  // blocks are variables); without a prior the oldest pose is held fixed (the gauge).
  SolveStats solve(bool use_imu);
  // Folds the oldest frame (its pose, speed/bias, and the landmarks anchored in it) into the
  // prior and removes it from the window. The landmarks folded in leave with it: their
  // observations in the frames that stay are already in the prior (see the definition).
  void marginalizeOldest(bool use_imu);
  // Removes the newest frame without keeping its information (a non-keyframe: VINS drops their
  // visual measurements too; its IMU is re-integrated from the previous keyframe).
  void dropNewest();
  // Clears frames, landmarks and prior.
  void clear();
  void clearPrior() {
    time_offset_prior_mean_s_ = *time_offset_s_;
    prior_.reset();
  }
  // Anchors the oldest frame with Gaussian priors around its current state; they join the
  // marginalisation prior when that frame leaves. Replaces anchors set before.
  void anchorOldest(const StartPrior& prior);
  // Landmarks usable by the optimisation (depth, and seen from two frames).
  [[nodiscard]] static bool usable(const Landmark& lm);
  // The camera-IMU time offset t_d (s; odometry/time_offset_factor.hpp), a state of IMU solves
  // when config.estimate_time_offset. It outlives clear(): a restart keeps the estimate.
  [[nodiscard]] double timeOffsetS() const { return *time_offset_s_; }
  // Sets t_d (the initialisation's estimate); it becomes the prior's mean until the
  // marginalisation prior holds t_d, with `sigma_s` as its 1-sigma when given (what the
  // initialisation observed), else vio.time_offset_sigma_s.
  void setTimeOffsetS(double t_d_s, std::optional<double> sigma_s = std::nullopt) {
    *time_offset_s_ = t_d_s;
    free_time_offsets_s_.clear();  // estimates of a window timed otherwise
    time_offset_prior_mean_s_ = t_d_s;
    time_offset_prior_sigma_s_ = sigma_s.value_or(config_.time_offset_sigma_s);
  }

 private:
  using FactorSink = std::function<void(std::shared_ptr<ceres::CostFunction>,
                                        const ceres::LossFunction*, std::vector<double*>)>;
  // Reprojection factors of one landmark (left, and right where matched) that evaluate at the
  // current state; returns how many were handed to `sink`.
  int landmarkFactors(Landmark& lm, const FactorSink& sink, bool with_time_offset) const;
  void timeOffsetFactors(Landmark& lm, WindowFrame& anchor, const FactorSink& sink) const;
  [[nodiscard]] bool estimatesTimeOffset(bool use_imu) const {
    return use_imu && config_.estimate_time_offset;
  }
  // Where a hold starts, t_d moves to the median of the latest free solves' values; after a free
  // solve, its value joins them.
  void startTimeOffsetHold();
  void recordFreeTimeOffset();
  // The prior on t_d (around its value when the window last started) while the marginalisation
  // prior does not hold t_d yet.
  [[nodiscard]] bool priorHoldsTimeOffset() const;
  [[nodiscard]] std::shared_ptr<ceres::CostFunction> timeOffsetPrior() const;
  [[nodiscard]] WindowFrame* find(std::uint64_t uid) const;
  void reintegrateIfNeeded();

  EstimatorConfig config_;
  StereoGeometry geometry_;
  PoseManifold pose_manifold_;
  std::shared_ptr<ceres::LossFunction> huber_;
  // One Ceres context for every solve (its set-up is not free at 10 solves per second).
  std::shared_ptr<ceres::Context> context_;
  std::deque<std::unique_ptr<WindowFrame>> frames_;
  LandmarkMap landmarks_;
  std::shared_ptr<const MarginalizationPrior> prior_;
  struct AnchorFactor {
    std::uint64_t frame_uid = 0;
    std::shared_ptr<ceres::CostFunction> cost;
    std::vector<double*> blocks;
    bool speed_bias = false;  // on the speed/bias block (only in IMU solves)
  };
  std::vector<AnchorFactor> anchors_;
  // Heap-held so that its address (the Ceres block) never moves with the window.
  std::unique_ptr<double> time_offset_s_ = std::make_unique<double>(0.0);
  double time_offset_prior_mean_s_ = 0.0;
  double time_offset_prior_sigma_s_;  // config_.time_offset_sigma_s unless set
  // t_d after each of the latest free solves (at most time_offset_hold_median_solves, newest
  // last), emptied when a hold starts: the hold keeps their median.
  std::deque<double> free_time_offsets_s_;
};

}  // namespace gvio::odometry
