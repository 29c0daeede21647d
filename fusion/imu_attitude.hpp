#pragma once
// An attitude an IMU reports with its measurements (an AHRS; REP 145: sensor_msgs/Imu orientation,
// the body's rotation from ENU), with the 1-sigma its covariance states for the yaw.
#include <Eigen/Core>
#include <cstdint>

namespace gvio::fusion {

struct ImuAttitude {
  std::int64_t t_ns = 0;
  Eigen::Matrix3d R_enu_b = Eigen::Matrix3d::Identity();
  double yaw_sigma_rad = 0.0;
};

}  // namespace gvio::fusion
