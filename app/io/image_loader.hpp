#pragma once
// Image files: lazy loading (frames hold paths, pixels are read only when a stage asks for them)
// and PNG writing.
#include <opencv2/core/mat.hpp>

#include <filesystem>

#include "odometry/measurements.hpp"

namespace gvio::io {

// Reads a greyscale 8-bit image and checks its size against the camera's calibration.
// Throws InputError naming the file when it is missing, unreadable or the wrong size.
cv::Mat loadGrayImage(const std::filesystem::path& file, const CameraModel& camera);

// Writes an 8-bit grey or BGR image as PNG, atomically, with fast compression (the simulator
// writes thousands). Throws InputError naming the file when encoding or writing fails.
void writePng(const std::filesystem::path& file, const cv::Mat& image);

}  // namespace gvio::io
