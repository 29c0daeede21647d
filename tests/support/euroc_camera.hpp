#pragma once
// The EuRoC MAV stereo rig's cameras (cam0/cam1 sensor.yaml): radial-tangential distortion,
// ~0.6 deg between the cameras, rotated in the body (IMU) frame, for tests that need a real
// distorted rig.
#include <Eigen/Geometry>

#include "odometry/measurements.hpp"

namespace gvio::test {

// Published calibrations are orthonormal to ~1e-9 only; Isometry3d::inverse assumes exactness.
inline Eigen::Isometry3d orthonormalPose(const Eigen::Matrix3d& R, const Eigen::Vector3d& t) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::Quaterniond(R).normalized().toRotationMatrix();
  T.translation() = t;
  return T;
}

inline CameraModel eurocCam0() {
  CameraModel c;
  c.name = "cam0";
  c.width_px = 752;
  c.height_px = 480;
  c.fx = 458.654, c.fy = 457.296, c.cx = 367.215, c.cy = 248.375;
  c.distortion = {-0.28340811, 0.07395907, 0.00019359, 1.76187114e-05};
  Eigen::Matrix3d R;
  R << 0.0148655429818, -0.999880929698, 0.00414029679422, 0.999557249008, 0.0149672133247,
      0.025715529948, -0.0257744366974, 0.00375618835797, 0.999660727178;
  c.T_b_c = orthonormalPose(R, {-0.0216401454975, -0.064676986768, 0.00981073058949});
  return c;
}

inline CameraModel eurocCam1() {
  CameraModel c;
  c.name = "cam1";
  c.width_px = 752;
  c.height_px = 480;
  c.fx = 457.587, c.fy = 456.134, c.cx = 379.999, c.cy = 255.238;
  c.distortion = {-0.28368365, 0.07451284, -0.00010473, -3.55590700e-05};
  Eigen::Matrix3d R;
  R << 0.0125552670891, -0.999755099723, 0.0182237714554, 0.999598781151, 0.0130119051815,
      0.0251588363115, -0.0253898008918, 0.0179005838253, 0.999517347078;
  c.T_b_c = orthonormalPose(R, {-0.0198435579556, 0.0453689425024, 0.00786212447038});
  return c;
}

}  // namespace gvio::test
