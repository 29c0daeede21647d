#pragma once
// EuRoC / ASL dataset folders: mav0/{cam0,cam1,imu0,gnss0,state_groundtruth_estimate0}.
#include <filesystem>

#include "io/dataset.hpp"

namespace gvio::io {

Dataset readEuroc(const std::filesystem::path& path, const ReaderConfig& config);

// The folder holding cam0/imu0/gnss0: path/mav0, or path itself. Empty when neither fits.
std::filesystem::path findEurocMav0(const std::filesystem::path& path);

}  // namespace gvio::io
