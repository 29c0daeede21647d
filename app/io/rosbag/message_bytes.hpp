#pragma once
// A check of an image message's serialised bytes before ROS deserialises them. ROS's
// VectorSerializer::read (ros/serialization.h) resizes a uint8[] to the length the message states
// and only then asks the stream for that many bytes: a 30 KB bag whose image declared 1 GB of
// pixels made the reader allocate and zero 1 GB before the overrun was noticed (found by
// fuzzing; up to 4 GB per message). The stated length is checked against the bytes that follow.
// http://wiki.ros.org/msg (serialisation: little-endian, strings and arrays with a u32 length)
#include <cstdint>
#include <vector>

namespace gvio::io::bag {

// Throws BagError when sensor_msgs/Image's fields (header, height, width, encoding, is_bigendian,
// step) run past `bytes`, or its `data` states more bytes than remain.
void checkImageBytes(const std::vector<std::uint8_t>& bytes);

// The same for sensor_msgs/CompressedImage (header, format, data).
void checkCompressedImageBytes(const std::vector<std::uint8_t>& bytes);

}  // namespace gvio::io::bag
