#pragma once
// A recorded drive as read from disk: calibration, IMU samples, GNSS fixes, and camera frames
// whose images stay on disk until asked for (memory does not grow with sequence length).
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core/mat.hpp>

#include "fusion/geodesy.hpp"
#include "fusion/imu_attitude.hpp"
#include "io/reader_config.hpp"
#include "odometry/measurements.hpp"
#include "odometry/trajectory.hpp"

namespace gvio::io {

enum class DatasetFormat { kKittiRaw, kEuroc, kNmea, kComma2k19, kRosbag, kRos2Bag };
std::string toString(DatasetFormat format);

// One camera trigger: the timestamp and one image path per camera (same order as cameras); no
// paths when the images live in a container (a bag) and the dataset's image store reads them.
struct FrameRecord {
  std::int64_t t_ns = 0;
  std::vector<std::filesystem::path> image_paths;
};

// Images inside a container file (a ROS bag) rather than one file each.
class ImageStore {
 public:
  virtual ~ImageStore() = default;
  // Frame `frame`'s image of camera `camera`, 8-bit grey, checked against the camera's size.
  // Throws InputError naming the container and the message. Safe to call from several threads.
  [[nodiscard]] virtual cv::Mat load(std::size_t frame, std::size_t camera,
                                     const CameraModel& model) const = 0;
  // Where a camera's images come from (e.g. "drive.bag:/cam0/image_raw"), to group messages.
  [[nodiscard]] virtual std::string source(std::size_t camera) const = 0;
};

// One topic of a ROS bag: what was read from it and what had to be repaired.
struct BagTopicUse {
  std::string role;  // cam0, cam1, imu, gnss
  std::string topic;
  std::string type;
  std::size_t messages = 0;          // in the bag
  std::size_t used = 0;              // kept (frames: paired; GNSS: with a fix)
  std::size_t out_of_order = 0;      // header stamp older than an earlier message's: sorted
  std::size_t duplicate_stamps = 0;  // a header stamp seen before: dropped
  std::size_t zero_stamps = 0;       // header stamp 0: the bag's receive time stood in
};

// Where one calibration value came from (gvio inspect prints them): e.g. {"cam0 intrinsics",
// "/cam0/camera_info (plumb_bob)"}, {"T_b_cam1", "/tf_static: imu_link -> cam1_optical"}.
struct CalibrationSource {
  std::string value;
  std::string source;
};

struct Dataset {
  DatasetFormat format = DatasetFormat::kKittiRaw;
  std::filesystem::path root;
  std::string variant;  // e.g. "sync" / "extract" for KITTI raw, "asl" for EuRoC
  std::vector<CameraModel> cameras;
  std::vector<FrameRecord> frames;
  std::vector<ImuSample> imu;
  // Attitudes the IMU itself reported (a bag's sensor_msgs/Imu orientation whose covariance
  // states a yaw sigma), in the IMU's clock: GNSS/INS may take its heading from them.
  std::vector<fusion::ImuAttitude> imu_attitude;
  std::optional<ImuNoise> imu_noise;  // when the dataset states it
  std::vector<GnssFix> gnss;
  std::string gnss_source;  // file the fixes came from, empty without GNSS
  std::optional<Trajectory> groundtruth;
  std::string groundtruth_source;
  // Set when the truth was converted into the local ENU frame at this origin (comma2k19), so that
  // a run in the same frame can be evaluated without alignment.
  std::optional<fusion::Lla> groundtruth_enu_origin;
  std::vector<std::string> warnings;  // non-fatal defects found while reading (also logged)
  // Kalibr's timeshift_cam_imu already added to every frame stamp (--calib), s.
  double camera_timeshift_s = 0.0;
  std::shared_ptr<const ImageStore> image_store;  // set when frames carry no image paths
  std::vector<BagTopicUse> bag_topics;            // ROS bags only
  std::vector<CalibrationSource> calibration_sources;
  // Why a recording that can carry calibration (a ROS 2 bag) did not calibrate its cameras.
  std::string calibration_missing;
  // The GNSS antenna in the body (IMU) frame when the recording states it (a ROS 2 bag's
  // /tf_static link to the NavSatFix frame); fusion.lever_arm_b, when set, overrides it.
  std::optional<Eigen::Vector3d> gnss_lever_arm_b;
};

// The calibrated image size of each camera against its first image, before any frame is
// processed: a mismatch is reported against the file the size came from (`calibration[c]` for
// camera c), naming the image too. An image that does not decode is left to loadFrameImage.
void checkFirstImageSizes(const Dataset& dataset,
                          const std::vector<std::filesystem::path>& calibration);

// Frame `frame`'s image of camera `camera` (from its file or the image store), 8-bit grey and
// size-checked. Throws InputError.
cv::Mat loadFrameImage(const Dataset& dataset, std::size_t frame, std::size_t camera);

// The calibrated image size of each camera against its first image, before any frame is
// processed: a mismatch is reported against the file the size came from (`calibration[c]` for
// camera c), naming the image too. An image that does not decode is left to loadFrameImage.
void checkFirstImageSizes(const Dataset& dataset,
                          const std::vector<std::filesystem::path>& calibration);
// The file's folder or the store's source: what a run groups unreadable images by.
std::string imageSource(const Dataset& dataset, std::size_t frame, std::size_t camera);

// Reads a dataset folder (or an NMEA file) after validating every line of every text file.
// `format` nullopt = detect. Throws InputError naming file and line on bad input.
Dataset readDataset(const std::filesystem::path& path, std::optional<DatasetFormat> format,
                    const ReaderConfig& config);

// Format detection from the folder layout; throws InputError when nothing matches.
DatasetFormat detectFormat(const std::filesystem::path& path);

// Parses "auto" (nullopt), "kitti-raw", "euroc", "nmea", "comma2k19", "rosbag", "ros2bag"; throws
// InvalidInput otherwise.
std::optional<DatasetFormat> parseDatasetFormat(const std::string& name);

}  // namespace gvio::io
