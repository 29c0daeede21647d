#pragma once
// Kalibr calibration files as Kalibr writes them (camchain.yaml, imu.yaml), for drives gvio
// writes itself (gvio simulate --format rosbag); io/kalibr.hpp reads them back.
#include <string>
#include <vector>

#include "odometry/measurements.hpp"

namespace gvio::io {

// camN blocks: pinhole intrinsics, radtan (zeros when none; OpenCV's fifth coefficient k3 only
// when 0) or equidistant distortion, resolution, T_cam_imu (= T_b_c^-1, the body being the IMU),
// T_cn_cnm1 from cam1 on, timeshift_cam_imu and rostopic. Throws InvalidInput otherwise.
std::string kalibrCamchainYaml(const std::vector<CameraModel>& cameras,
                               const std::vector<std::string>& topics, double timeshift_cam_imu_s);

// imu0 block: noise densities, random walks, rate and rostopic.
std::string kalibrImuYaml(const ImuNoise& noise, double rate_hz, const std::string& topic);

}  // namespace gvio::io
