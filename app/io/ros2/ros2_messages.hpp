#pragma once
// The ROS 2 messages gvio reads from ROS 2 bags (and its simulator writes to them), decoded from
// and encoded to CDR (io/ros2/cdr.hpp) without ROS. Field order is that of the .msg files of
// ROS 2 Humble and Jazzy (common_interfaces, rcl_interfaces, geometry2; the two releases serialise
// these types identically).
//
// Decoders take one message's serialised bytes as a bag stores them (encapsulation header
// included) and throw Ros2Error, and nothing else, for any defect: data ending inside a field, a
// stated length longer than the bytes left (checked before anything is allocated for it), a
// stamp's nanosec >= 1e9, a bool or is_bigendian byte other than 0 or 1, a string without its NUL,
// more than 3 bytes left after the last field (a message of another type), an encapsulation other
// than plain CDR. Numbers are returned as they are (NaN and infinities included: callers check).
//
// Return types: the project's ROS 1 structs (io/rosbag/bag_file.hpp) wrapped with what they lack,
// above all the header's frame_id, which every decoded type carries (callers look transforms up
// by it). Stamps: t.header_ns is the header's stamp; t.receive_ns is left 0 for the caller (the
// bag's log time). Encoders write CDR_LE (encapsulation 00 01 00 00); decoding what they wrote
// gives back the same values, doubles bit for bit.
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "io/rosbag/bag_file.hpp"

namespace gvio::io::ros2 {

inline constexpr const char* kRos2ImageType = "sensor_msgs/msg/Image";
inline constexpr const char* kRos2CompressedImageType = "sensor_msgs/msg/CompressedImage";
inline constexpr const char* kRos2ImuType = "sensor_msgs/msg/Imu";
inline constexpr const char* kRos2NavSatFixType = "sensor_msgs/msg/NavSatFix";
inline constexpr const char* kRos2CameraInfoType = "sensor_msgs/msg/CameraInfo";
inline constexpr const char* kRos2TfType = "tf2_msgs/msg/TFMessage";

// sensor_msgs/msg/Imu: imu.gyr_radps is angular_velocity, imu.acc_mps2 linear_acceleration,
// imu.orientation_* the orientation and its covariance.
struct Ros2Imu {
  bag::ImuMessage imu;
  std::array<double, 9> angular_velocity_covariance{};
  std::array<double, 9> linear_acceleration_covariance{};
  std::string frame_id;
};

// sensor_msgs/msg/NavSatFix: fix.status is status.status, fix.covariance_type
// position_covariance_type; service is status.service (bits: GPS 1, GLONASS 2, COMPASS 4,
// GALILEO 8).
struct Ros2NavSatFix {
  bag::NavSatFixMessage fix;
  std::uint16_t service = 0;
  std::string frame_id;
};

// sensor_msgs/msg/Image (image.compressed false) or sensor_msgs/msg/CompressedImage (true).
struct Ros2Image {
  bag::ImageMessage image;
  std::string frame_id;
};

// sensor_msgs/msg/RegionOfInterest.
struct RegionOfInterest {
  std::uint32_t x_offset = 0, y_offset = 0, height = 0, width = 0;
  bool do_rectify = false;
};

// sensor_msgs/msg/CameraInfo: k (3x3), r (3x3) and p (3x4) row major.
struct CameraInfoMessage {
  bag::Stamps t;
  std::string frame_id;
  std::uint32_t height = 0, width = 0;
  std::string distortion_model;  // e.g. "plumb_bob", "rational_polynomial", "equidistant"
  std::vector<double> d;
  std::array<double, 9> k{};
  std::array<double, 9> r{};
  std::array<double, 12> p{};
  std::uint32_t binning_x = 0, binning_y = 0;
  RegionOfInterest roi;
};

// One geometry_msgs/msg/TransformStamped of a tf2_msgs/msg/TFMessage: the pose of
// child_frame_id in frame_id (the parent) at t.header_ns.
struct TransformMessage {
  bag::Stamps t;
  std::string frame_id;
  std::string child_frame_id;
  std::array<double, 3> translation{};
  std::array<double, 4> rotation_xyzw{0.0, 0.0, 0.0, 1.0};
};

// The stamp of a message that starts with a std_msgs/Header, from its first 12 bytes only
// (encapsulation header, sec, nanosec): sec * 1e9 + nanosec, sec negative too. Throws Ros2Error
// when there are fewer bytes or nanosec >= 1e9.
std::int64_t headerStampNs(const std::uint8_t* data, std::size_t size);

Ros2Imu decodeImu(std::span<const std::uint8_t> message);
Ros2NavSatFix decodeNavSatFix(std::span<const std::uint8_t> message);
Ros2Image decodeImage(std::span<const std::uint8_t> message);
Ros2Image decodeCompressedImage(std::span<const std::uint8_t> message);
CameraInfoMessage decodeCameraInfo(std::span<const std::uint8_t> message);
std::vector<TransformMessage> decodeTfMessage(std::span<const std::uint8_t> message);

// Encoders throw Ros2Error for a value the message cannot hold: a stamp outside int32 seconds, a
// NavSatFix status outside int8 or covariance type outside uint8, an image whose `compressed`
// does not match the encoder, a string or sequence longer than a u32 can count.
std::vector<std::uint8_t> encodeImu(const Ros2Imu& message);
std::vector<std::uint8_t> encodeNavSatFix(const Ros2NavSatFix& message);
std::vector<std::uint8_t> encodeImage(const Ros2Image& message);
std::vector<std::uint8_t> encodeCompressedImage(const Ros2Image& message);
std::vector<std::uint8_t> encodeCameraInfo(const CameraInfoMessage& message);
std::vector<std::uint8_t> encodeTfMessage(std::span<const TransformMessage> transforms);

// The type's definition in MCAP's "ros2msg" schema encoding, as rosbag2_storage_mcap writes it:
// the type's .msg text, then each dependency once (depth first, in name order) after a line of
// 80 '=' and a line "MSG: pkg/Type". Accepts the ROS 2 name (sensor_msgs/msg/Imu) of the types
// above; throws Ros2Error for any other.
std::string ros2MessageDefinition(const std::string& type);

// "sensor_msgs/msg/Image" -> "sensor_msgs/Image" (the ROS 1 form used elsewhere in gvio); a name
// without the "/msg/" part is returned as it is.
std::string ros1TypeName(const std::string& type);

}  // namespace gvio::io::ros2
