#pragma once
// The TUM VI stereo rig's 512x512 fisheye cameras (Kalibr's pinhole-equi calibration of the 512 px
// EuRoC-format export, T_b_c as OKVIS's TUM VI configuration prints it): equidistant
// (Kannala-Brandt) lenses of ~190 deg, ~2.7 deg between the cameras, for tests that need a real
// fisheye rig.
#include <Eigen/Geometry>

#include "odometry/measurements.hpp"
#include "support/euroc_camera.hpp"

namespace gvio::test {

inline CameraModel tumviCam0() {
  CameraModel c;
  c.name = "cam0";
  c.width_px = 512;
  c.height_px = 512;
  c.fx = 190.97847715128717, c.fy = 190.9733070521226;
  c.cx = 254.93170605935475, c.cy = 256.8974428996504;
  c.distortion_model = Distortion::kEquidistant;
  c.distortion = {0.0034823894022493434, 0.0007150348452162257, -0.0020532361418706202,
                  0.00020293673591811182};
  Eigen::Matrix3d R;
  R << -0.99953071, 0.00744168, -0.02971511, 0.0294408, -0.03459565, -0.99896766, -0.00846201,
      -0.99937369, 0.03436032;
  c.T_b_c = orthonormalPose(R, {0.04536566, -0.071996, -0.04478181});
  return c;
}

inline CameraModel tumviCam1() {
  CameraModel c;
  c.name = "cam1";
  c.width_px = 512;
  c.height_px = 512;
  c.fx = 190.44236969414825, c.fy = 190.4344384721956;
  c.cx = 252.59949716835982, c.cy = 254.91723064636983;
  c.distortion_model = Distortion::kEquidistant;
  c.distortion = {0.0034003170790442797, 0.001766278153469831, -0.00266312569781606,
                  0.0003299517423931039};
  Eigen::Matrix3d R;
  R << -0.99951678, 0.00803569, -0.03002713, 0.03012473, 0.01231336, -0.9994703, -0.0076617,
      -0.9998919, -0.01254948;
  c.T_b_c = orthonormalPose(R, {-0.05566603, -0.07010225, -0.0475471});
  return c;
}

}  // namespace gvio::test
