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

}  // namespace gvio::test
