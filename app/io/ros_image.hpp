#pragma once
// sensor_msgs/Image and sensor_msgs/CompressedImage payloads turned into the 8-bit grey images
// the tracker takes, and back (gvio simulate --format rosbag). Conversions follow cv_bridge's:
// colour to grey with OpenCV's weights, 16-bit to 8-bit by 1/256.
#include <opencv2/core/mat.hpp>

#include <string>

#include "io/rosbag/bag_file.hpp"

namespace gvio::io {

// Encodings accepted from sensor_msgs/Image (named in errors).
inline constexpr const char* kRosImageEncodings =
    "mono8, 8UC1, mono16, 16UC1, bgr8, rgb8, bgra8, rgba8, bayer_rggb8, bayer_bggr8, bayer_gbrg8, "
    "bayer_grbg8 (and their 16-bit forms)";

// Throws InvalidInput saying what is wrong: an unsupported encoding or compressed format, a
// step or data size that does not fit the image, an undecodable compressed payload.
cv::Mat rosImageToGray(const bag::ImageMessage& message);

// An 8-bit grey image as sensor_msgs/Image mono8, or (png = true) as a PNG CompressedImage.
bag::ImageMessage grayToRosImage(const cv::Mat& gray, bool png);

}  // namespace gvio::io
