#pragma once
// KITTI's rectified left grey camera (drive 2011_10_03, 1241x376) and stereo baseline, for tests
// and benchmarks that need a realistic automotive camera.
#include "odometry/measurements.hpp"

namespace gvio::test {

inline CameraModel kittiRectifiedCamera() {
  CameraModel c;
  c.name = "left";
  c.width_px = 1241;
  c.height_px = 376;
  c.fx = c.fy = 718.856;
  c.cx = 607.19;
  c.cy = 185.22;
  return c;
}
inline constexpr double kKittiBaselineM = 0.54;

// The same camera looking forward from a body with x forward, y left, z up (camera x right, y
// down, z forward), 1 m ahead of and 0.7 m above the body origin.
inline CameraModel kittiForwardCamera() {
  CameraModel c = kittiRectifiedCamera();
  Eigen::Matrix3d R;
  R << 0, 0, 1, -1, 0, 0, 0, -1, 0;
  c.T_b_c.linear() = R;
  c.T_b_c.translation() = Eigen::Vector3d(1.0, 0.0, 0.7);
  return c;
}

}  // namespace gvio::test
