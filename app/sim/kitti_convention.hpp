#pragma once
// KITTI conventions the simulator reproduces: the rectified grey stereo camera, the calibration
// files of the raw dataset, and the conversion of KITTI odometry poses (left camera in the first
// camera's frame) to body (IMU) poses in ENU.
#include <Eigen/Geometry>
#include <filesystem>
#include <string>

#include "odometry/trajectory.hpp"
#include "render/camera.hpp"

namespace gvio::sim {

// KITTI's rectified grey camera: 1241 x 376, fx = fy = 718.856, cx 607.1928, cy 185.2157.
render::PinholeIntrinsics kittiIntrinsics();
inline constexpr double kKittiBaselineM = 0.537;

// The three calib_*.txt files of a raw drive for an ideal stereo pair with intrinsics K: the IMU ->
// velodyne -> camera chain of KITTI's 2011_09_26 calibration, cam1 0.537 m to the right of cam0,
// no distortion (raw = rectified).
struct KittiCalibrationText {
  std::string cam_to_cam, imu_to_velo, velo_to_cam;
};
KittiCalibrationText kittiCalibrationText(const render::PinholeIntrinsics& K, bool stereo);
// The same, written atomically into `dir`.
void writeKittiCalibration(const std::filesystem::path& dir, const render::PinholeIntrinsics& K,
                           bool stereo);

// T_c0_b: the body (IMU) frame in the left camera's frame, from the same calibration chain.
Eigen::Isometry3d kittiCamFromImu();

// KITTI odometry ground truth (cam0 poses, world = first cam0 frame: x right, y down, z forward)
// to body poses in ENU: the world's forward axis points `heading_deg` counter-clockwise from east.
Trajectory kittiCameraToEnuBody(const Trajectory& T_kw_c0, double heading_deg);

}  // namespace gvio::sim
