#pragma once
// A drive recorded as a bag (ROS 1 or ROS 2): sensor_msgs/Image or CompressedImage (one camera or
// a stereo pair), sensor_msgs/Imu and sensor_msgs/NavSatFix. Topics are chosen by type when that
// is unambiguous, else named in config (dataset.topics.*). Every stream is ordered by header stamp
// (messages out of order are sorted and counted; repeated stamps dropped and counted; a zero stamp
// replaced by the receive time). Images stay in the bag and are decoded on request.
#include <Eigen/Core>
#include <array>
#include <filesystem>
#include <memory>
#include <optional>

#include "io/bag_source.hpp"
#include "io/dataset.hpp"

namespace gvio::io {

// Fills `ds` (its format, root and variant already set) from `source`: frames, cameras (names and
// image sizes; intrinsics come from elsewhere), IMU, GNSS, bag_topics, warnings. Throws InputError
// naming `file` (and topic) for a missing or wrongly typed topic, ambiguous topics, an unsupported
// image encoding (checked on the first image), an unreadable message.
// A message's quaternion (x y z w: geometry_msgs/Quaternion) as a rotation, nullopt unless its
// norm is 1 within 1e-3 (a rotation written with a few digits passes, a damaged one does not).
std::optional<Eigen::Matrix3d> messageRotation(const std::array<double, 4>& xyzw);

void readBagDataset(const std::filesystem::path& file,
                    const std::shared_ptr<const BagSource>& source, const ReaderConfig& config,
                    Dataset& ds);

}  // namespace gvio::io
