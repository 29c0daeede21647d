#pragma once
// KITTI raw calibration files ("key: v1 v2 ...") and the camera <- IMU extrinsic chain
//   T_ci_imu = T_ci_cam0 * T_cam0_velo * T_velo_imu
// (Geiger et al., "Vision meets Robotics: The KITTI Dataset", IJRR 2013, eqs. 3-5).
#include <cstddef>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "odometry/measurements.hpp"

namespace gvio::io {

class KittiCalibFile {
 public:
  explicit KittiCalibFile(const std::filesystem::path& file);  // throws InputError

  [[nodiscard]] bool has(const std::string& key) const { return entries_.count(key) > 0; }
  // The key's values as numbers; throws InputError naming file and line when the key is missing,
  // a value is malformed or the count differs from `count`.
  [[nodiscard]] std::vector<double> numbers(const std::string& key, std::size_t count) const;
  [[nodiscard]] const std::filesystem::path& path() const { return path_; }
  // The line the key is on, 0 when it is missing.
  [[nodiscard]] std::size_t lineOf(const std::string& key) const;

 private:
  struct Entry {
    std::string text;
    std::size_t line = 0;
  };
  std::filesystem::path path_;
  std::map<std::string, Entry> entries_;
};

struct KittiCalibPaths {
  std::filesystem::path cam_to_cam, imu_to_velo, velo_to_cam;
};

// Looks for the three calib_*.txt files in the drive folder, then in its parent (the layout of
// the KITTI raw download). Throws InputError naming the first file found in neither.
KittiCalibPaths findKittiCalib(const std::filesystem::path& drive_dir);

// Camera models (body = IMU frame) for the given camera indices (0..3). `rectified` selects the
// S_rect/P_rect/R_rect_00 calibration of `sync` drives; otherwise S/K/D/R/T of `extract` drives.
std::vector<CameraModel> readKittiCameras(const KittiCalibPaths& paths, const std::vector<int>& ids,
                                          bool rectified);

}  // namespace gvio::io
