#pragma once
// gvio simulate --format ros2bag: the drive as a ROS 2 bag folder, recorded as a ROS 2 rig
// records it, with the calibration inside: the output folder is the bag (metadata.yaml and
// drive_0.mcap, or drive_0.db3 with sim.ros2bag_storage sqlite3) holding
//   /cam0/image_raw, /cam1/image_raw  sensor_msgs/msg/Image mono8 (frames cam0, cam1)
//   /cam0/camera_info, /cam1/camera_info  one per image (plumb_bob, no distortion; P with the
//                                     stereo baseline, as a calibrated stereo driver publishes)
//   /imu0                             sensor_msgs/msg/Imu (frame imu; no orientation)
//   /gnss/fix                         sensor_msgs/msg/NavSatFix (frame gnss)
//   /tf_static                        imu -> cam0, imu -> cam1, imu -> gnss (the antenna)
// in time order. Kalibr camchain.yaml and imu.yaml of the same values are written beside it (the
// IMU noise has no place in a bag). Numbers carry the EuRoC layout's precision, as for ROS 1.
#include <filesystem>
#include <memory>
#include <vector>

#include <opencv2/core/mat.hpp>

#include "io/ros2/ros2_bag_writer.hpp"
#include "odometry/measurements.hpp"
#include "sim/imu_synth.hpp"
#include "sim/sim_config.hpp"

namespace gvio::sim {

class Ros2BagOutput {
 public:
  // Starts the bag; IMU and GNSS messages are written as the images' time reaches them.
  Ros2BagOutput(const std::filesystem::path& out, const SimConfig& config,
                const std::vector<CameraModel>& cameras, std::vector<ImuSimSample> imu,
                std::vector<GnssFix> fixes);
  ~Ros2BagOutput();
  void writeImage(std::int64_t t_ns, std::size_t camera, const cv::Mat& gray);
  // The remaining messages, metadata.yaml, camchain.yaml and imu.yaml.
  void finish(const ImuNoise& noise, double imu_rate_hz);

 private:
  void writeSensorsUpTo(std::int64_t t_ns);

  std::filesystem::path out_;
  std::vector<CameraModel> cameras_;  // as the EuRoC layout writes them
  std::vector<ImuSimSample> imu_;
  std::vector<GnssFix> fixes_;
  std::size_t next_imu_ = 0, next_fix_ = 0;
  bool tf_written_ = false;
  Eigen::Vector3d lever_arm_b_;
  std::unique_ptr<io::ros2::Ros2BagWriter> writer_;
  struct Topics {
    std::size_t images[2] = {0, 0}, infos[2] = {0, 0}, imu = 0, gnss = 0, tf = 0;
  } topics_;
};

}  // namespace gvio::sim
