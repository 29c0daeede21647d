#pragma once
// The IMU's mounting in the vehicle from the direction it moves in (fusion/gnss_ins.hpp): a land
// vehicle moves along its forward axis (the non-holonomic constraint, Groves section 14.3.3), so
// the filter's velocity in the IMU body frame, v_b = R^T v, points along the vehicle's forward
// axis expressed in the body: e = R_v_b^T (1, 0, 0). Its principal direction over many epochs
// (the dominant eigenvector of sum u u^T of the unit directions, so reversing does not cancel
// forward driving; the sign is the majority's) corrects the configured mount by the smallest
// rotation that takes e onto the forward axis: yaw and pitch of the mount are estimated, roll
// about the forward axis is not observable this way and stays as configured.
#include <Eigen/Core>
#include <optional>

namespace gvio::fusion {

struct MountConfig {
  double min_speed_mps = 0.5;      // slower epochs say little about the direction
  int min_samples = 30;            // epochs before an estimate is given
  double min_concentration = 0.9;  // share of the scatter along the principal axis
};

struct MountEstimate {
  Eigen::Matrix3d R_v_b = Eigen::Matrix3d::Identity();  // IMU body -> vehicle
  Eigen::Vector3d rpy_rad = Eigen::Vector3d::Zero();    // R_v_b = Rz(yaw) Ry(pitch) Rx(roll)
  int samples = 0;
  double concentration = 0.0;
};

class MountEstimator {
 public:
  explicit MountEstimator(const MountConfig& config) : config_(config) {}
  // The body-frame velocity at one epoch (ignored below min_speed_mps).
  void add(const Eigen::Vector3d& v_b_mps);
  // `R_v_b_config` the configured mount, corrected as little as the direction of travel needs.
  [[nodiscard]] std::optional<MountEstimate> estimate(const Eigen::Matrix3d& R_v_b_config) const;
  [[nodiscard]] int samples() const { return samples_; }

 private:
  MountConfig config_;
  Eigen::Matrix3d scatter_ = Eigen::Matrix3d::Zero();
  Eigen::Vector3d sum_ = Eigen::Vector3d::Zero();
  int samples_ = 0;
};

}  // namespace gvio::fusion
