#pragma once
// Image files: lazy loading (frames hold paths, pixels are read only when a stage asks for them)
// and PNG writing.
#include <opencv2/core/mat.hpp>

#include <filesystem>
#include <string>
#include <vector>

#include "odometry/measurements.hpp"

namespace gvio::io {

// Reads a greyscale 8-bit image and checks its size against the camera's calibration.
// Throws InputError naming the file when it is missing, unreadable or the wrong size.
cv::Mat loadGrayImage(const std::filesystem::path& file, const CameraModel& camera);

// Decodes a PNG or a JPEG (told by its signature) to 8-bit grey. Returns an empty image and sets
// `defect` for anything else, a damaged PNG, or data the decoder refuses. Other formats never
// reach OpenCV: cv::imdecode tries every decoder it was built with, and some of them abort the
// process on crafted data (GDCM's DICOM reader asserts: found by fuzzing ROS CompressedImages).
cv::Mat decodeGrayPngOrJpeg(const std::vector<unsigned char>& bytes, std::string& defect);

// loadGrayImage without the size check: an empty image when the file cannot be read or decoded.
cv::Mat tryLoadGrayImage(const std::filesystem::path& file);

// Writes an 8-bit grey or BGR image as PNG, atomically, with fast compression (the simulator
// writes thousands). Throws InputError naming the file when encoding or writing fails.
void writePng(const std::filesystem::path& file, const cv::Mat& image);

}  // namespace gvio::io
