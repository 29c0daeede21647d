#pragma once
// Visual-inertial alignment for initialisation (VINS-Mono, Qin et al. 2018, section V-B): given
// body poses from vision alone over a short window and the IMU preintegrated between them, solve
// the gyroscope bias, then every frame's velocity and the gravity vector in the visual frame (and
// the metric scale for a monocular camera) by linear least squares, refine gravity on the sphere
// |g| = 9.81 m/s^2, and return the rotation that makes the visual frame gravity-aligned.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <memory>
#include <optional>
#include <vector>

#include "odometry/imu_preintegration.hpp"

namespace gvio::odometry {

struct AlignmentFrame {
  Eigen::Matrix3d R_v_b = Eigen::Matrix3d::Identity();  // body in the visual frame
  // The body position in the visual frame is s * p_v_b + lever_v: for stereo, p_v_b is the body
  // position itself (s = 1, no lever); for a monocular camera p_v_b is the camera position at the
  // visual scale and lever_v = R_v_c t_c_b the metric camera-to-body lever arm, which does not
  // scale (VINS-Mono eq. 17 with its extrinsic term).
  Eigen::Vector3d p_v_b = Eigen::Vector3d::Zero();
  Eigen::Vector3d lever_v = Eigen::Vector3d::Zero();
  // IMU from the previous frame to this one (null for the first frame).
  std::shared_ptr<ImuPreintegration> preintegration;
};

struct AlignmentResult {
  Eigen::Vector3d gyr_bias = Eigen::Vector3d::Zero();
  Eigen::Vector3d g_v = Eigen::Vector3d::Zero();  // gravity in the visual frame, |g| = 9.81
  std::vector<Eigen::Vector3d> v_v;               // velocity of each frame in the visual frame
  double scale = 1.0;                             // metric / visual (1 unless estimated)
  double scale_rel_sigma = 0.0;                   // 1-sigma of the scale / scale (if estimated)
  Eigen::Matrix3d R_w_v = Eigen::Matrix3d::Identity();  // visual frame -> gravity-aligned world
  double gravity_norm_before_refinement = 0.0;
  // 1-sigma of the gravity direction (rad), the largest over the two tilt axes: the refined
  // solve's covariance scaled by its residual variance (unit weights, as the scale's). It is
  // conservative: about 1.7x the actual spread on noisy synthetic windows.
  double tilt_sigma_rad = 0.0;
  // Camera-IMU time offset (when asked for): how much the frames' stamps lag the exposures the
  // visual poses belong to (s), and its posterior 1-sigma.
  double t_d_s = 0.0;
  double t_d_sigma_s = 0.0;
  bool t_d_observed = false;
  std::vector<Eigen::Vector3d> w_b;  // body rate at each stamp (rad/s), when t_d was estimated
};

// A Gaussian prior on the camera-IMU time offset t_d (s): stamps = exposures + t_d.
struct TimeOffsetPrior {
  double mean_s = 0.0;
  double sigma_s = 0.05;
  // The window's estimate is taken only when its posterior 1-sigma is below this; else t_d stays
  // at the prior's mean (a straight drive at constant speed says nothing about t_d, and a weakly
  // informed estimate moved it by 5-17 ms on such drives).
  double max_sigma_s = 0.005;
};

struct GyroBiasTimeOffset {
  Eigen::Vector3d gyr_bias = Eigen::Vector3d::Zero();
  double t_d_s = 0.0;
  double t_d_sigma_s = 0.0;  // posterior 1-sigma of the joint solve
  bool observed = false;     // t_d_sigma_s <= max_sigma_s: t_d_s is the window's estimate
};

// Least-squares gyroscope bias from the visual relative rotations (VINS-Mono eq. 15).
Eigen::Vector3d solveGyroBias(const std::vector<AlignmentFrame>& frames);

// The gyroscope bias and the camera-IMU time offset together (Qin and Shen, IROS 2018, moved into
// the initialisation): the visual poses belong to the exposures, t_d before the stamps the IMU was
// preintegrated between, so to first order in t_d and the bias change
//   Log(dR_ij(bg)^T R_i^T R_j) = dR_dbg dbg + (dR_ij^T w_i - w_j) t_d
// with w the body rate at each stamp (from the preintegrated rotations). Residual noise is taken
// from the fit itself (unit weights, as the velocity solve); needs >= 3 frames. A window that does
// not observe t_d (no change of rotation rate) gives the prior's mean and solveGyroBias's bias.
GyroBiasTimeOffset solveGyroBiasAndTimeOffset(const std::vector<AlignmentFrame>& frames,
                                              const TimeOffsetPrior& prior);

// Body angular rate (rad/s) at each frame's stamp, interpolated between the mean rates of the
// preintegrated intervals around it (their midpoints), extrapolated at the window's ends.
std::vector<Eigen::Vector3d> stampRates(const std::vector<AlignmentFrame>& frames);

// Full alignment; re-integrates the preintegrations at the solved gyroscope bias. Returns nullopt
// when the linear problem is degenerate, the gravity estimate is implausible (|g| off by more
// than `gravity_tolerance` relative) or, when estimating the scale, its relative 1-sigma (normal
// equations inverse times the residual variance) exceeds `max_scale_rel_sigma`: at constant
// velocity the scale is unobservable, and a wrong scale is worse than waiting for more motion.
// With `time_offset`, t_d is estimated with the gyroscope bias (solveGyroBiasAndTimeOffset) and
// the velocity solve takes each visual position as the body's t_d before its stamp.
std::optional<AlignmentResult> alignVisualInertial(
    std::vector<AlignmentFrame>& frames, bool estimate_scale, double gravity_tolerance = 0.1,
    double max_scale_rel_sigma = 0.05,
    const std::optional<TimeOffsetPrior>& time_offset = std::nullopt);

// Rotation that takes the gravity direction g_v to (0, 0, -|g|) with no added yaw about it.
Eigen::Matrix3d gravityAlignment(const Eigen::Vector3d& g_v);

}  // namespace gvio::odometry
