#pragma once
// GNSS fixes from a file of their own, for any dataset (gvio run / inspect --gnss-file): NMEA 0183
// (io/nmea.hpp), an RTKLIB solution (.pos, io/rtklib_pos.hpp) or EuRoC-style CSV
// (io/euroc.hpp readGnssCsv). The format is told by the content: a first line starting with '$'
// is NMEA, with '%' RTKLIB, anything else CSV. Every reader names the file and line of bad input.
#include <filesystem>
#include <string>
#include <vector>

#include "io/dataset.hpp"
#include "io/reader_config.hpp"
#include "odometry/measurements.hpp"

namespace gvio::io {

struct GnssFileData {
  std::vector<GnssFix> fixes;  // UTC ns since the Unix epoch, strictly increasing
  std::string format;          // "nmea", "rtklib-pos" or "csv"
  std::vector<std::string> warnings;
};

GnssFileData readGnssFile(const std::filesystem::path& file, const ReaderConfig& config);

// Replaces the dataset's fixes with the file's (gnss_source, warnings); warns when none of the
// fixes falls within the dataset's frames or IMU samples (a clock in another time scale).
void useGnssFile(Dataset& ds, const std::filesystem::path& file, const ReaderConfig& config);

}  // namespace gvio::io
