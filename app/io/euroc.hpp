#pragma once
// EuRoC / ASL dataset folders: mav0/{cam0,cam1,imu0,gnss0,state_groundtruth_estimate0}.
#include <filesystem>
#include <string>
#include <vector>

#include "io/dataset.hpp"

namespace gvio::io {

Dataset readEuroc(const std::filesystem::path& path, const ReaderConfig& config);

// GNSS fixes as EuRoC-style CSV (gnss0/data.csv, also what `gvio simulate` writes as
// gnss/data.csv): "#timestamp [ns],lat_deg,lon_deg,height_m,sigma_h_m,sigma_v_m", stamps strictly
// increasing. Out-of-range positions and non-positive sigmas are skipped with a counted warning
// (never used); NaN or malformed numbers are fatal (InputError with file and line).
std::vector<GnssFix> readGnssCsv(const std::filesystem::path& file,
                                 std::vector<std::string>& warnings);

// The folder holding cam0/imu0/gnss0: path/mav0, or path itself. Empty when neither fits.
std::filesystem::path findEurocMav0(const std::filesystem::path& path);

}  // namespace gvio::io
