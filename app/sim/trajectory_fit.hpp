#pragma once
// A smooth, twice-differentiable continuous-time body trajectory fitted to stamped poses, so the
// simulator can sample positions, velocities, accelerations, orientations and body rates
// analytically (IMU synthesis needs exact derivatives, not finite differences of noisy poses).
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <vector>

#include "odometry/trajectory.hpp"

namespace gvio::sim {

struct BodyState {
  Eigen::Vector3d p_w = Eigen::Vector3d::Zero();        // position of the body origin, world (ENU)
  Eigen::Vector3d v_w = Eigen::Vector3d::Zero();        // velocity, world
  Eigen::Vector3d a_w = Eigen::Vector3d::Zero();        // acceleration, world
  Eigen::Matrix3d R_w_b = Eigen::Matrix3d::Identity();  // body orientation
  Eigen::Vector3d omega_b = Eigen::Vector3d::Zero();    // angular rate in the body frame (rad/s)

  [[nodiscard]] Eigen::Isometry3d pose() const;
};

struct FitOptions {
  double knot_spacing_s = 0.25;  // control-point spacing of the splines
  double smoothing = 1e-2;       // weight of the curvature penalty (0 = pure least squares)
};

struct FitReport {
  double position_rms_m = 0.0, position_max_m = 0.0;      // fitted vs given positions
  double rotation_rms_deg = 0.0, rotation_max_deg = 0.0;  // fitted vs given orientations
  std::size_t poses = 0;
};

class ContinuousTrajectory {
 public:
  // Fits to body poses T_w_b with timestamps (strictly increasing, >= 4 poses). Throws
  // InvalidInput otherwise.
  static ContinuousTrajectory fit(const Trajectory& T_w_b, const FitOptions& options = {});

  [[nodiscard]] BodyState at(std::int64_t t_ns) const;  // clamped to [t0, t1]
  [[nodiscard]] std::int64_t t0_ns() const { return t0_ns_; }
  [[nodiscard]] std::int64_t t1_ns() const { return t1_ns_; }
  [[nodiscard]] const FitReport& report() const { return report_; }

 private:
  std::int64_t t0_ns_ = 0, t1_ns_ = 0;
  double knot_spacing_s_ = 0.25;
  // Uniform cubic B-spline control points: x, y, z, roll, pitch, unwrapped yaw (ZYX Euler).
  std::vector<Eigen::Matrix<double, 6, 1>> control_;
  FitReport report_;
};

}  // namespace gvio::sim
