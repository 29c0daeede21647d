#pragma once
// A drive recorded as a ROS1 bag (gvio --format rosbag, or any file ending in .bag or starting
// with the bag magic): sensor_msgs/Image or CompressedImage (one camera or a stereo pair),
// sensor_msgs/Imu and sensor_msgs/NavSatFix. Topics are chosen by type when that is unambiguous,
// else named in config (dataset.topics.*). Every stream is ordered by header stamp (messages out
// of order are sorted and counted; repeated stamps dropped and counted). Images stay in the bag
// and are decoded on request. A bag holds no camera-IMU calibration: images need --calib (Kalibr).
#include <filesystem>

#include "io/dataset.hpp"

namespace gvio::io {

// True when the file starts with the ROS bag magic "#ROSBAG V".
bool looksLikeRosbag(const std::filesystem::path& file);

// Throws InputError naming the bag (and topic) for an unreadable bag, a missing or wrongly typed
// topic, ambiguous topics, an unsupported image encoding (checked on the first image).
Dataset readRosbag(const std::filesystem::path& bag, const ReaderConfig& config);

}  // namespace gvio::io
