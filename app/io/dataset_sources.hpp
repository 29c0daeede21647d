#pragma once
// A dataset with what the command line adds to it: Kalibr calibration (--calib) and GNSS from a
// separate file (--gnss-file). gvio run and gvio inspect open datasets through this one path.
#include <filesystem>
#include <optional>
#include <vector>

#include "io/dataset.hpp"

namespace gvio::io {

struct DatasetSources {
  std::filesystem::path dataset;
  std::optional<DatasetFormat> format;  // nullopt: detect
  std::vector<std::filesystem::path> calib_files;
  std::optional<std::filesystem::path> gnss_file;
  // A run needs calibrated cameras; inspect summarises a bag without them.
  bool require_calibration = true;
};

// Reads the calibration first (a camchain's rostopic names a bag's image topics, an imu.yaml's its
// IMU topic, where the config names none), then the dataset, applies the calibration, then the
// GNSS file. Throws InputError; a bag with images but no camera calibration is refused when
// calibration is required, else left with a warning.
Dataset openDataset(const DatasetSources& sources, ReaderConfig config);

}  // namespace gvio::io
