#pragma once
// Simulator settings (YAML section `sim:`), plain struct with defaults. Per-run choices that users
// vary every time (duration, GNSS grade, outages, seed, output format) are CLI flags instead.
#include <Eigen/Core>
#include <string>

#include "odometry/measurements.hpp"

namespace gvio::sim {

struct SimConfig {
  // Geodetic origin of the local ENU frame (KITTI 00's first GPS fix).
  double origin_lat_deg = 48.98253, origin_lon_deg = 8.39035, origin_h_m = 116.4;
  // Heading of the KITTI world's forward (camera z) axis in ENU, degrees counter-clockwise from
  // east.
  double heading_deg = 0.0;
  double camera_rate_hz = 10.0;
  double imu_rate_hz = 100.0;
  double gnss_rate_hz = 1.0;  // 1, 5 or 10
  Eigen::Vector3d gnss_lever_arm_m{0.0, 0.0,
                                   0.8};  // antenna in the body frame (x fwd, y left, z up)
  double image_noise_dn = 2.0;            // Gaussian pixel noise, digital numbers (1 sigma)
  bool exposure_change = false;           // slow sinusoidal gain change
  double exposure_amplitude = 0.15;       // relative gain amplitude
  double exposure_period_s = 20.0;
  // The right camera's gain relative to the left's: a rig whose cameras expose independently
  // (1: the same exposure).
  double right_camera_gain = 1.0;
  bool motion_blur = false;
  double exposure_time_s = 0.004;  // blur integrates over this interval
  int blur_samples = 4;            // renders averaged per blurred frame
  // Camera stamps = exposure time + this (a camera clock the IMU's is off from; issue 16's
  // time-offset test): images are rendered at the exposure, written with the shifted stamp.
  double camera_time_offset_s = 0.0;
  double knot_spacing_s = 0.25;  // trajectory spline
  double smoothing = 1e-2;
  int texture_size_px = 512;
  std::string world_style = "street";  // sim/world.hpp: WorldStyle (--world-style overrides)
  // Per-drive IMU noise: each of the four imu.* densities times its own multiplier, drawn
  // log-uniformly in [min, max] by seed (1, 1: the imu.* values exactly).
  double imu_noise_scale_min = 1.0, imu_noise_scale_max = 1.0;
  // Per-drive turn-on biases, 1 sigma per axis (0: the IMU starts unbiased).
  double imu_turn_on_acc_bias_mps2 = 0.0;
  double imu_turn_on_gyr_bias_radps = 0.0;
  // --format ros2bag: the storage plugin (mcap, sqlite3) and, for MCAP, the chunk compression
  // (none, lz4, zstd).
  std::string ros2bag_storage = "mcap";
  std::string ros2bag_compression = "lz4";

  void validate() const;  // throws InvalidInput naming the key
};

}  // namespace gvio::sim
