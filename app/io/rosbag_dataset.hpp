#pragma once
// A drive recorded as a ROS1 bag (gvio --format rosbag, or any file ending in .bag or starting
// with the bag magic), read through librosbag_storage; topics, ordering and pairing as every bag
// (io/bag_dataset.hpp). A ROS 1 bag holds no camera-IMU calibration: images need --calib (Kalibr).
#include <filesystem>

#include "io/dataset.hpp"

namespace gvio::io {

// True when the file starts with the ROS bag magic "#ROSBAG V".
bool looksLikeRosbag(const std::filesystem::path& file);

// Throws InputError naming the bag (and topic) for an unreadable bag, a missing or wrongly typed
// topic, ambiguous topics, an unsupported image encoding (checked on the first image).
Dataset readRosbag(const std::filesystem::path& bag, const ReaderConfig& config);

}  // namespace gvio::io
