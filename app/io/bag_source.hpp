#pragma once
// What the bag dataset reader needs from a recording, whichever ROS wrote it: its topics and the
// sensor messages on them. ROS 1 bags (librosbag_storage) and ROS 2 bags (MCAP or sqlite3 storage,
// CDR messages) both offer it, so topic choice, stamp ordering and stereo pairing are one code.
// Every method throws bag::BagError (ros2::Ros2Error is one) saying what is wrong.
#include <optional>
#include <string>
#include <vector>

#include "io/rosbag/bag_file.hpp"

namespace gvio::io {

class BagSource {
 public:
  virtual ~BagSource() = default;
  // Types in ROS 1 form (sensor_msgs/Image) whichever ROS wrote the bag.
  [[nodiscard]] virtual std::vector<bag::TopicInfo> topics() const = 0;
  [[nodiscard]] virtual std::vector<bag::ImuMessage> readImu(const std::string& topic) const = 0;
  [[nodiscard]] virtual std::vector<bag::NavSatFixMessage> readNavSatFix(
      const std::string& topic) const = 0;
  // An image topic's stamps in storage order; message i of that order is readImage(topic, i).
  [[nodiscard]] virtual std::vector<bag::Stamps> imageStamps(const std::string& topic) const = 0;
  // Safe to call from several threads.
  [[nodiscard]] virtual bag::ImageMessage readImage(const std::string& topic,
                                                    std::size_t index) const = 0;
};

}  // namespace gvio::io
