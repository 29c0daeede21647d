#pragma once
// A small rectified stereo rig for the window's landmark tests (500 px focal length, 640 x 480,
// 0.5 m baseline, body = left camera) and exact pinhole projections through it.
#include <Eigen/Core>
#include <Eigen/Geometry>

#include "odometry/landmarks.hpp"

namespace gvio::test {

inline constexpr double kStereoRigBaselineM = 0.5;

inline odometry::StereoGeometry stereoRig() {
  odometry::StereoGeometry g;
  g.left = {500.0, 500.0, 320.0, 240.0, Eigen::Isometry3d::Identity()};
  g.right = g.left;
  g.right.T_b_c.translation() = Eigen::Vector3d(kStereoRigBaselineM, 0.0, 0.0);
  g.stereo = true;
  g.baseline_m = kStereoRigBaselineM;
  return g;
}

// The pixel where `view` (on the body at T_w_b) sees the world point p_w.
inline Eigen::Vector2d project(const odometry::PinholeView& view, const Eigen::Isometry3d& T_w_b,
                               const Eigen::Vector3d& p_w) {
  const Eigen::Vector3d p_c = (T_w_b * view.T_b_c).inverse() * p_w;
  return {view.fx * p_c.x() / p_c.z() + view.cx, view.fy * p_c.y() / p_c.z() + view.cy};
}

}  // namespace gvio::test
