#pragma once
// A recorded drive as read from disk: calibration, IMU samples, GNSS fixes, and camera frames
// whose images stay on disk until asked for (memory does not grow with sequence length).
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "fusion/geodesy.hpp"
#include "io/reader_config.hpp"
#include "odometry/measurements.hpp"
#include "odometry/trajectory.hpp"

namespace gvio::io {

enum class DatasetFormat { kKittiRaw, kEuroc, kNmea, kComma2k19 };
std::string toString(DatasetFormat format);

// One camera trigger: the timestamp and one image path per camera (same order as cameras).
struct FrameRecord {
  std::int64_t t_ns = 0;
  std::vector<std::filesystem::path> image_paths;
};

struct Dataset {
  DatasetFormat format = DatasetFormat::kKittiRaw;
  std::filesystem::path root;
  std::string variant;  // e.g. "sync" / "extract" for KITTI raw, "asl" for EuRoC
  std::vector<CameraModel> cameras;
  std::vector<FrameRecord> frames;
  std::vector<ImuSample> imu;
  std::optional<ImuNoise> imu_noise;  // when the dataset states it
  std::vector<GnssFix> gnss;
  std::string gnss_source;  // file the fixes came from, empty without GNSS
  std::optional<Trajectory> groundtruth;
  std::string groundtruth_source;
  // Set when the truth was converted into the local ENU frame at this origin (comma2k19), so that
  // a run in the same frame can be evaluated without alignment.
  std::optional<fusion::Lla> groundtruth_enu_origin;
  std::vector<std::string> warnings;  // non-fatal defects found while reading (also logged)
};

// Reads a dataset folder (or an NMEA file) after validating every line of every text file.
// `format` nullopt = detect. Throws InputError naming file and line on bad input.
Dataset readDataset(const std::filesystem::path& path, std::optional<DatasetFormat> format,
                    const ReaderConfig& config);

// Format detection from the folder layout; throws InputError when nothing matches.
DatasetFormat detectFormat(const std::filesystem::path& path);

// Parses "auto" (nullopt), "kitti-raw", "euroc", "nmea", "comma2k19"; throws InvalidInput
// otherwise.
std::optional<DatasetFormat> parseDatasetFormat(const std::string& name);

}  // namespace gvio::io
