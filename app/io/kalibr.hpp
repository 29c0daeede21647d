#pragma once
// Calibration from Kalibr's output files, for any dataset format (gvio run / inspect --calib):
//  - camchain.yaml: cam0, cam1, ... each with camera_model (pinhole), intrinsics [fu fv pu pv],
//    distortion_model (radtan [k1 k2 p1 p2], equidistant [k1 k2 k3 k4]: fisheye, rectified with
//    cv::fisheye, or none; fov is refused for now, with that reason), distortion_coeffs,
//    resolution [w h], T_cam_imu (4x4, IMU -> camera), T_cn_cnm1 (camera n relative to n-1; used
//    when T_cam_imu is absent, checked against it when both are there), timeshift_cam_imu
//    (t_imu = t_cam + shift);
//  - imu.yaml: accelerometer/gyroscope noise densities and random walks, at the top level (Kalibr's
//    input) or under imu0 (its output).
// The body frame is the IMU's, as everywhere in gvio: T_b_c = T_cam_imu^-1. Errors name the file
// and line (InputError).
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "io/dataset.hpp"
#include "odometry/measurements.hpp"

namespace gvio::io {

struct KalibrCalibration {
  std::vector<CameraModel> cameras;  // cam0, cam1, ... in order (name "cam0", ...)
  double timeshift_cam_imu_s = 0.0;  // cam0's (every camera of a chain shares the trigger)
  std::optional<ImuNoise> imu_noise;
  // The rostopic each camera (and the IMU) was calibrated from; empty where the file names none.
  std::vector<std::string> camera_topics;
  std::string imu_topic;
  std::vector<std::string> warnings;
};

// Reads every file (a camchain, an IMU file, or both in one) into one calibration. Throws
// InputError when no file holds a camera or IMU block, or on a bad block.
KalibrCalibration readKalibr(const std::vector<std::filesystem::path>& files);

// Replaces the dataset's cameras (when the calibration has them: as many as the dataset's; a
// camera whose size came from its images (a bag) must match the calibrated resolution) and
// IMU noise (when given), and shifts every frame stamp by timeshift_cam_imu into the IMU's clock.
void applyKalibr(Dataset& ds, const KalibrCalibration& calibration);

}  // namespace gvio::io
