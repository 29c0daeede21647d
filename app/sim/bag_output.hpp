#pragma once
// gvio simulate --format rosbag: the drive as one ROS1 bag plus Kalibr calibration, the way a
// real rig's recording arrives. drive.bag holds /cam0/image_raw (and /cam1/image_raw) as mono8
// sensor_msgs/Image, /imu0 sensor_msgs/Imu and /gnss/fix sensor_msgs/NavSatFix (diagonal ENU
// covariance from the fix's sigmas); camchain.yaml and imu.yaml name those topics. Numbers carry
// the precision of the EuRoC layout's text (IMU to 1e-12, latitude and longitude to 1e-10 deg,
// heights and sigmas to 0.1 mm, T_b_c to 1e-12), so one seed gives one drive in either layout.
#include <filesystem>
#include <memory>
#include <vector>

#include <opencv2/core/mat.hpp>

#include "io/rosbag/bag_file.hpp"
#include "odometry/measurements.hpp"
#include "sim/imu_synth.hpp"

namespace gvio::sim {

inline constexpr const char* kBagFileName = "drive.bag";

class BagOutput {
 public:
  // Starts `out`/drive.bag (written to a temporary name, renamed by finish()).
  explicit BagOutput(const std::filesystem::path& out);
  void writeImage(std::int64_t t_ns, std::size_t camera, const cv::Mat& gray);
  // Writes the IMU and GNSS messages, closes the bag and writes camchain.yaml and imu.yaml.
  void finish(const std::vector<ImuSimSample>& imu, const std::vector<GnssFix>& fixes,
              const std::vector<CameraModel>& cameras, const ImuNoise& noise, double imu_rate_hz);

 private:
  std::filesystem::path out_, temporary_;
  std::unique_ptr<io::bag::BagWriter> writer_;
};

// An IMU sample and a fix as either bag format carries them (stamped with their measurement
// time), at the EuRoC text's precision.
io::bag::ImuMessage bagImuMessage(const ImuSimSample& s);
io::bag::NavSatFixMessage bagFixMessage(const GnssFix& f);

// A camera pose as the EuRoC layout writes it (12 decimals per entry).
Eigen::Isometry3d asEurocWrites(const Eigen::Isometry3d& T_b_c);

}  // namespace gvio::sim
