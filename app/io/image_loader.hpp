#pragma once
// Lazy image loading: frames hold paths, pixels are read only when a stage asks for them.
#include <opencv2/core/mat.hpp>

#include <filesystem>

#include "odometry/measurements.hpp"

namespace gvio::io {

// Reads a greyscale 8-bit image and checks its size against the camera's calibration.
// Throws InputError naming the file when it is missing, unreadable or the wrong size.
cv::Mat loadGrayImage(const std::filesystem::path& file, const CameraModel& camera);

}  // namespace gvio::io
