#pragma once
// Any defect found while reading (or failure while writing) a ROS 2 bag's storage or a message in
// it: what went wrong, without the file name (callers add it, as for ROS 1 bags, whose BagError it
// is, so that the dataset reader shared by both handles one kind of error).
#include "io/rosbag/bag_file.hpp"

namespace gvio::io::ros2 {

class Ros2Error : public bag::BagError {
 public:
  using bag::BagError::BagError;
};

}  // namespace gvio::io::ros2
