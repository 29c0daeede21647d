#pragma once
// Writers of the simulator's output layouts. KITTI raw ("extract" style: 100 Hz oxts carrying the
// IMU and the true lat/lon/alt/attitude) and EuRoC/ASL (mav0/...), both read back by io/.
#include <opencv2/core/mat.hpp>

#include <filesystem>
#include <string>
#include <vector>

#include "fusion/geodesy.hpp"
#include "render/camera.hpp"
#include "sim/gnss_synth.hpp"
#include "sim/imu_synth.hpp"
#include "sim/trajectory_fit.hpp"

namespace gvio::sim {

// KITTI raw: oxts/data/%010d.txt + timestamps.txt, one record per IMU sample: true position and
// attitude (ENU, KITTI's roll/pitch/yaw), true velocities, the simulated IMU in a*/w* fields.
void writeKittiOxts(const std::filesystem::path& drive, const std::vector<ImuSimSample>& imu,
                    const ContinuousTrajectory& trajectory, const fusion::EnuFrame& enu);
void writeKittiImageStamps(const std::filesystem::path& drive, int camera,
                           const std::vector<std::int64_t>& t_ns);
std::filesystem::path kittiImagePath(const std::filesystem::path& drive, int camera,
                                     std::size_t index);

// imu_truth.csv: t_ns, true specific force and rate (noise-free) and the true biases, per sample.
void writeImuTruth(const std::filesystem::path& file, const std::vector<ImuSimSample>& imu);

// EuRoC: camera folder name "cam0"/"cam1".
std::filesystem::path eurocImagePath(const std::filesystem::path& root, int camera,
                                     std::int64_t t_ns);
void writeEurocCamera(const std::filesystem::path& root, int camera,
                      const std::vector<std::int64_t>& t_ns, const render::PinholeIntrinsics& K,
                      const Eigen::Isometry3d& T_b_c, double rate_hz);
void writeEurocImu(const std::filesystem::path& root, const std::vector<ImuSimSample>& imu,
                   const ImuNoise& noise, double rate_hz);
void writeEurocGnss(const std::filesystem::path& root, const std::vector<GnssFix>& fixes);
// state_groundtruth_estimate0/data.csv: t, p, q (w x y z), v, gyro bias, accel bias at IMU stamps.
void writeEurocTruth(const std::filesystem::path& root, const std::vector<ImuSimSample>& imu,
                     const ContinuousTrajectory& trajectory);

}  // namespace gvio::sim
