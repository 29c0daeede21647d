#include "io/dataset.hpp"

#include <fmt/format.h>

#include <fstream>
#include <opencv2/imgcodecs.hpp>

#include "io/comma2k19.hpp"
#include "io/euroc.hpp"
#include "io/image_loader.hpp"
#include "io/input_error.hpp"
#include "io/kitti_raw.hpp"
#include "io/nmea.hpp"
#include "io/ros2/ros2_bag.hpp"
#include "io/ros2_dataset.hpp"
#include "io/rosbag_dataset.hpp"

namespace gvio::io {
namespace fs = std::filesystem;
namespace {

bool looksLikeNmeaFile(const fs::path& file) {
  std::ifstream in(file);
  std::string line;
  for (int i = 0; i < 20 && std::getline(in, line); ++i) {
    if (line.rfind("\xEF\xBB\xBF", 0) == 0) line.erase(0, 3);  // UTF-8 BOM
    if (line.rfind("$", 0) == 0) return true;
  }
  return false;
}

Dataset readNmeaDataset(const fs::path& file, const ReaderConfig& config) {
  NmeaLog log = readNmea(file, config);
  Dataset ds;
  ds.format = DatasetFormat::kNmea;
  ds.root = file;
  ds.variant = "nmea0183";
  ds.gnss = std::move(log.fixes);
  ds.gnss_source = file.string();
  ds.warnings = std::move(log.warnings);
  return ds;
}

}  // namespace

std::string toString(DatasetFormat format) {
  switch (format) {
    case DatasetFormat::kKittiRaw:
      return "kitti-raw";
    case DatasetFormat::kEuroc:
      return "euroc";
    case DatasetFormat::kNmea:
      return "nmea";
    case DatasetFormat::kComma2k19:
      return "comma2k19";
    case DatasetFormat::kRosbag:
      return "rosbag";
    case DatasetFormat::kRos2Bag:
      return "ros2bag";
  }
  return "unknown";
}

std::optional<DatasetFormat> parseDatasetFormat(const std::string& name) {
  if (name == "auto") return std::nullopt;
  if (name == "kitti-raw") return DatasetFormat::kKittiRaw;
  if (name == "euroc") return DatasetFormat::kEuroc;
  if (name == "nmea") return DatasetFormat::kNmea;
  if (name == "comma2k19") return DatasetFormat::kComma2k19;
  if (name == "rosbag") return DatasetFormat::kRosbag;
  if (name == "ros2bag") return DatasetFormat::kRos2Bag;
  throw InvalidInput("unknown dataset format '" + name +
                     "' (expected auto, kitti-raw, euroc, nmea, comma2k19, rosbag or ros2bag)");
}

DatasetFormat detectFormat(const fs::path& path) {
  std::error_code ec;
  if (!fs::exists(path, ec)) throw InputError(path, 0, "dataset not found");
  if (fs::is_regular_file(path, ec)) {
    if (path.extension() == ".bag" || looksLikeRosbag(path)) return DatasetFormat::kRosbag;
    if (path.extension() == ".mcap" || path.extension() == ".db3" || ros2::looksLikeRos2Bag(path)) {
      return DatasetFormat::kRos2Bag;
    }
    if (looksLikeNmeaFile(path)) return DatasetFormat::kNmea;
    throw InputError(path, 0,
                     "a file that is neither a ROS bag (ROS 1 .bag, ROS 2 .mcap or .db3) nor an "
                     "NMEA 0183 log (expected a dataset folder)");
  }
  if (ros2::looksLikeRos2Bag(path)) return DatasetFormat::kRos2Bag;
  if (looksLikeKittiRaw(path)) return DatasetFormat::kKittiRaw;
  if (!findEurocMav0(path).empty()) return DatasetFormat::kEuroc;
  if (looksLikeComma2k19(path)) return DatasetFormat::kComma2k19;
  throw InputError(
      path, 0,
      "unrecognised dataset layout (expected a KITTI raw drive with oxts/ or image_00/, "
      "an EuRoC folder with mav0/, a comma2k19 folder with csv/imu.csv, or a ROS 2 bag folder "
      "with metadata.yaml)");
}

Dataset readDataset(const fs::path& path, std::optional<DatasetFormat> format,
                    const ReaderConfig& config) {
  config.validate();
  const DatasetFormat f = format ? *format : detectFormat(path);
  Dataset ds;
  switch (f) {
    case DatasetFormat::kKittiRaw:
      ds = readKittiRaw(path, config);
      break;
    case DatasetFormat::kEuroc:
      ds = readEuroc(path, config);
      break;
    case DatasetFormat::kNmea:
      ds = readNmeaDataset(path, config);
      break;
    case DatasetFormat::kComma2k19:
      ds = readComma2k19(path, config);
      break;
    case DatasetFormat::kRosbag:
      ds = readRosbag(path, config);
      break;
    case DatasetFormat::kRos2Bag:
      ds = readRos2Bag(path, config);
      break;
  }
  if (ds.frames.empty() && ds.imu.empty() && ds.gnss.empty()) {
    throw InputError(path, 0, "dataset holds no camera frames, IMU samples or GNSS fixes");
  }
  return ds;
}

void checkFirstImageSizes(const Dataset& ds,
                          const std::vector<std::filesystem::path>& calibration) {
  if (ds.frames.empty()) return;
  for (std::size_t c = 0; c < ds.cameras.size() && c < calibration.size(); ++c) {
    if (c >= ds.frames.front().image_paths.size()) break;
    const std::filesystem::path& first = ds.frames.front().image_paths[c];
    const cv::Mat image = tryLoadGrayImage(first);
    const CameraModel& cam = ds.cameras[c];
    if (!image.empty() && (image.cols != cam.width_px || image.rows != cam.height_px)) {
      throw InputError(
          calibration[c], 0,
          fmt::format("{} is {}x{} but the calibration of {} says {}x{}", first.string(),
                      image.cols, image.rows, cam.name, cam.width_px, cam.height_px));
    }
  }
}

cv::Mat loadFrameImage(const Dataset& ds, std::size_t frame, std::size_t camera) {
  if (ds.image_store) return ds.image_store->load(frame, camera, ds.cameras.at(camera));
  return loadGrayImage(ds.frames.at(frame).image_paths.at(camera), ds.cameras.at(camera));
}

std::string imageSource(const Dataset& ds, std::size_t frame, std::size_t camera) {
  if (ds.image_store) return ds.image_store->source(camera);
  return ds.frames.at(frame).image_paths.at(camera).parent_path().string();
}

}  // namespace gvio::io
