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
};

// Least-squares gyroscope bias from the visual relative rotations (VINS-Mono eq. 15).
Eigen::Vector3d solveGyroBias(const std::vector<AlignmentFrame>& frames);

// Full alignment; re-integrates the preintegrations at the solved gyroscope bias. Returns nullopt
// when the linear problem is degenerate, the gravity estimate is implausible (|g| off by more
// than `gravity_tolerance` relative) or, when estimating the scale, its relative 1-sigma (normal
// equations inverse times the residual variance) exceeds `max_scale_rel_sigma`: at constant
// velocity the scale is unobservable, and a wrong scale is worse than waiting for more motion.
std::optional<AlignmentResult> alignVisualInertial(std::vector<AlignmentFrame>& frames,
                                                   bool estimate_scale,
                                                   double gravity_tolerance = 0.1,
                                                   double max_scale_rel_sigma = 0.05);

// Rotation that takes the gravity direction g_v to (0, 0, -|g|) with no added yaw about it.
Eigen::Matrix3d gravityAlignment(const Eigen::Vector3d& g_v);

}  // namespace gvio::odometry
