#pragma once
// A drive recorded as a ROS 2 bag (gvio --format ros2bag, or a folder with metadata.yaml, or an
// .mcap or .db3 file): the messages of io/bag_dataset.hpp in CDR, from MCAP or sqlite3 storage,
// and the calibration the bag carries (io/ros2/bag_calibration.hpp): intrinsics from each image
// topic's CameraInfo, extrinsics from /tf_static. Kalibr files (--calib) replace what the bag says.
#include <filesystem>

#include "io/dataset.hpp"

namespace gvio::io {

// Throws InputError naming the bag folder, metadata.yaml or the storage file for an unreadable
// bag, and as readBagDataset does for its topics and messages.
Dataset readRos2Bag(const std::filesystem::path& path, const ReaderConfig& config);

}  // namespace gvio::io
