#include "io/ros2/ros2_messages.hpp"

#include <fmt/format.h>

#include <limits>
#include <string_view>

#include "io/ros2/cdr.hpp"
#include "io/ros2/ros2_error.hpp"

namespace gvio::io::ros2 {

namespace {

constexpr std::int64_t kNsPerS = 1'000'000'000;

// Each decoder and encoder below lists the fields in the order of the type's .msg file; nested
// types (Header, Quaternion, ...) are their fields inline, as CDR has it.

// ---- std_msgs/Header: builtin_interfaces/Time stamp (int32 sec, uint32 nanosec), frame_id ----

std::int64_t readStamp(CdrReader& in) {
  const std::int32_t sec = in.i32("header.stamp.sec");
  const std::uint32_t nanosec = in.u32("header.stamp.nanosec");
  // Time.msg: nanosec is in [0, 1e9). |sec| * 1e9 < 2.2e18 fits in int64 with room to spare.
  if (nanosec >= kNsPerS) {
    in.fail(fmt::format("its header.stamp.nanosec {} is not below 1e9", nanosec));
  }
  return std::int64_t{sec} * kNsPerS + std::int64_t{nanosec};
}

void writeStamp(CdrWriter& out, std::int64_t stamp_ns) {
  // Time.msg: -1.7 s is {sec: -2, nanosec: 3e8}; seconds round down.
  std::int64_t sec = stamp_ns / kNsPerS;
  std::int64_t nanosec = stamp_ns % kNsPerS;
  if (nanosec < 0) {
    sec -= 1;
    nanosec += kNsPerS;
  }
  if (sec < std::numeric_limits<std::int32_t>::min() ||
      sec > std::numeric_limits<std::int32_t>::max()) {
    throw Ros2Error(
        fmt::format("stamp {} ns is outside builtin_interfaces/Time's int32 seconds", stamp_ns));
  }
  out.i32(static_cast<std::int32_t>(sec));
  out.u32(static_cast<std::uint32_t>(nanosec));
}

std::int64_t readHeader(CdrReader& in, std::string& frame_id) {
  const std::int64_t stamp_ns = readStamp(in);
  frame_id = in.string("header.frame_id");
  return stamp_ns;
}

void writeHeader(CdrWriter& out, std::int64_t stamp_ns, std::string_view frame_id) {
  writeStamp(out, stamp_ns);
  out.string(frame_id);
}

// A byte that must be 0 or 1 though its type is uint8 (Image.is_bigendian).
bool flagByte(CdrReader& in, const char* field) {
  const std::uint8_t value = in.u8(field);
  if (value > 1) in.fail(fmt::format("its {} is {}, not 0 or 1", field, value));
  return value == 1;
}

template <typename Int>
Int checkedNarrow(int value, const char* field) {
  if (value < std::numeric_limits<Int>::min() || value > std::numeric_limits<Int>::max()) {
    throw Ros2Error(fmt::format("{} cannot hold {}", field, value));
  }
  return static_cast<Int>(value);
}

void checkKind(const Ros2Image& message, bool compressed, const char* type) {
  if (message.image.compressed != compressed) {
    throw Ros2Error(fmt::format("an image with compressed = {} cannot be encoded as a {}",
                                message.image.compressed, type));
  }
}

// geometry_msgs/TransformStamped's least size: a header whose frame_id has length 0 (12 bytes),
// an empty child_frame_id (4) and the Transform (7 float64, 56); padding only adds to it.
constexpr std::size_t kMinTransformBytes = 12 + 4 + 56;

TransformMessage readTransformStamped(CdrReader& in) {
  TransformMessage out;
  out.t.header_ns = readHeader(in, out.frame_id);
  out.child_frame_id = in.string("child_frame_id");
  out.translation = in.f64Array<3>("transform.translation");
  out.rotation_xyzw = in.f64Array<4>("transform.rotation");
  return out;
}

void writeTransformStamped(CdrWriter& out, const TransformMessage& message) {
  writeHeader(out, message.t.header_ns, message.frame_id);
  out.string(message.child_frame_id);
  out.f64s(message.translation);
  out.f64s(message.rotation_xyzw);
}

}  // namespace

std::int64_t headerStampNs(const std::uint8_t* data, std::size_t size) {
  CdrReader in({data, size}, "message with a std_msgs/Header");
  return readStamp(in);
}

// ---- sensor_msgs/msg/Imu ----

Ros2Imu decodeImu(std::span<const std::uint8_t> message) {
  CdrReader in(message, kRos2ImuType);
  Ros2Imu out;
  out.imu.t.header_ns = readHeader(in, out.frame_id);
  out.imu.orientation_xyzw = in.f64Array<4>("orientation");
  out.imu.orientation_covariance = in.f64Array<9>("orientation_covariance");
  out.imu.gyr_radps = in.f64Array<3>("angular_velocity");
  out.angular_velocity_covariance = in.f64Array<9>("angular_velocity_covariance");
  out.imu.acc_mps2 = in.f64Array<3>("linear_acceleration");
  out.linear_acceleration_covariance = in.f64Array<9>("linear_acceleration_covariance");
  in.expectEnd();
  return out;
}

std::vector<std::uint8_t> encodeImu(const Ros2Imu& message) {
  CdrWriter out;
  writeHeader(out, message.imu.t.header_ns, message.frame_id);
  out.f64s(message.imu.orientation_xyzw);
  out.f64s(message.imu.orientation_covariance);
  out.f64s(message.imu.gyr_radps);
  out.f64s(message.angular_velocity_covariance);
  out.f64s(message.imu.acc_mps2);
  out.f64s(message.linear_acceleration_covariance);
  return out.take();
}

// ---- sensor_msgs/msg/NavSatFix ----

Ros2NavSatFix decodeNavSatFix(std::span<const std::uint8_t> message) {
  CdrReader in(message, kRos2NavSatFixType);
  Ros2NavSatFix out;
  out.fix.t.header_ns = readHeader(in, out.frame_id);
  out.fix.status = in.i8("status.status");
  out.service = in.u16("status.service");
  out.fix.lat_deg = in.f64("latitude");
  out.fix.lon_deg = in.f64("longitude");
  out.fix.alt_m = in.f64("altitude");
  out.fix.covariance_enu_m2 = in.f64Array<9>("position_covariance");
  out.fix.covariance_type = in.u8("position_covariance_type");
  in.expectEnd();
  return out;
}

std::vector<std::uint8_t> encodeNavSatFix(const Ros2NavSatFix& message) {
  const bag::NavSatFixMessage& fix = message.fix;
  CdrWriter out;
  writeHeader(out, fix.t.header_ns, message.frame_id);
  out.i8(checkedNarrow<std::int8_t>(fix.status, "NavSatFix status.status (int8)"));
  out.u16(message.service);
  out.f64(fix.lat_deg);
  out.f64(fix.lon_deg);
  out.f64(fix.alt_m);
  out.f64s(fix.covariance_enu_m2);
  out.u8(checkedNarrow<std::uint8_t>(fix.covariance_type,
                                     "NavSatFix position_covariance_type (uint8)"));
  return out.take();
}

// ---- sensor_msgs/msg/Image and sensor_msgs/msg/CompressedImage ----

Ros2Image decodeImage(std::span<const std::uint8_t> message) {
  CdrReader in(message, kRos2ImageType);
  Ros2Image out;
  bag::ImageMessage& image = out.image;
  image.t.header_ns = readHeader(in, out.frame_id);
  image.compressed = false;
  image.height = in.u32("height");
  image.width = in.u32("width");
  image.encoding = in.string("encoding");
  image.big_endian = flagByte(in, "is_bigendian");
  image.step = in.u32("step");
  image.data = in.u8Sequence("data");
  in.expectEnd();
  return out;
}

std::vector<std::uint8_t> encodeImage(const Ros2Image& message) {
  checkKind(message, false, kRos2ImageType);
  const bag::ImageMessage& image = message.image;
  CdrWriter out;
  writeHeader(out, image.t.header_ns, message.frame_id);
  out.u32(image.height);
  out.u32(image.width);
  out.string(image.encoding);
  out.u8(image.big_endian ? 1 : 0);
  out.u32(image.step);
  out.u8Sequence(image.data);
  return out.take();
}

Ros2Image decodeCompressedImage(std::span<const std::uint8_t> message) {
  CdrReader in(message, kRos2CompressedImageType);
  Ros2Image out;
  out.image.t.header_ns = readHeader(in, out.frame_id);
  out.image.compressed = true;
  out.image.format = in.string("format");
  out.image.data = in.u8Sequence("data");
  in.expectEnd();
  return out;
}

std::vector<std::uint8_t> encodeCompressedImage(const Ros2Image& message) {
  checkKind(message, true, kRos2CompressedImageType);
  CdrWriter out;
  writeHeader(out, message.image.t.header_ns, message.frame_id);
  out.string(message.image.format);
  out.u8Sequence(message.image.data);
  return out.take();
}

// ---- sensor_msgs/msg/CameraInfo ----

CameraInfoMessage decodeCameraInfo(std::span<const std::uint8_t> message) {
  CdrReader in(message, kRos2CameraInfoType);
  CameraInfoMessage out;
  out.t.header_ns = readHeader(in, out.frame_id);
  out.height = in.u32("height");
  out.width = in.u32("width");
  out.distortion_model = in.string("distortion_model");
  out.d = in.f64Sequence("d");
  out.k = in.f64Array<9>("k");
  out.r = in.f64Array<9>("r");
  out.p = in.f64Array<12>("p");
  out.binning_x = in.u32("binning_x");
  out.binning_y = in.u32("binning_y");
  out.roi.x_offset = in.u32("roi.x_offset");
  out.roi.y_offset = in.u32("roi.y_offset");
  out.roi.height = in.u32("roi.height");
  out.roi.width = in.u32("roi.width");
  out.roi.do_rectify = in.boolean("roi.do_rectify");
  in.expectEnd();
  return out;
}

std::vector<std::uint8_t> encodeCameraInfo(const CameraInfoMessage& message) {
  CdrWriter out;
  writeHeader(out, message.t.header_ns, message.frame_id);
  out.u32(message.height);
  out.u32(message.width);
  out.string(message.distortion_model);
  out.f64Sequence(message.d);
  out.f64s(message.k);
  out.f64s(message.r);
  out.f64s(message.p);
  out.u32(message.binning_x);
  out.u32(message.binning_y);
  out.u32(message.roi.x_offset);
  out.u32(message.roi.y_offset);
  out.u32(message.roi.height);
  out.u32(message.roi.width);
  out.boolean(message.roi.do_rectify);
  return out.take();
}

// ---- tf2_msgs/msg/TFMessage: geometry_msgs/TransformStamped[] transforms ----

std::vector<TransformMessage> decodeTfMessage(std::span<const std::uint8_t> message) {
  CdrReader in(message, kRos2TfType);
  const std::size_t count = in.sequenceLength("transforms", kMinTransformBytes);
  // Not reserved: the vector grows with the transforms actually read.
  std::vector<TransformMessage> out;
  for (std::size_t i = 0; i < count; ++i) out.push_back(readTransformStamped(in));
  in.expectEnd();
  return out;
}

std::vector<std::uint8_t> encodeTfMessage(std::span<const TransformMessage> transforms) {
  CdrWriter out;
  out.sequenceLength(transforms.size());
  for (const TransformMessage& transform : transforms) writeTransformStamped(out, transform);
  return out.take();
}

}  // namespace gvio::io::ros2
