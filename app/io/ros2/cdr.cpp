#include "io/ros2/cdr.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <bit>
#include <limits>

#include "io/ros2/ros2_error.hpp"

namespace gvio::io::ros2 {

namespace {

// DDS-RTPS 2.5 section 10 "Serialized Payload Representation": the encapsulation identifiers.
// ROS 2's rmw implementations write plain CDR (0x0000/0x0001) for every message type.
constexpr std::uint16_t kCdrBe = 0x0000;
constexpr std::uint16_t kCdrLe = 0x0001;

const char* encapsulationName(std::uint16_t id) {
  switch (id) {
    case 0x0002:
      return "PL_CDR_BE, parameter-list CDR";
    case 0x0003:
      return "PL_CDR_LE, parameter-list CDR";
    case 0x0006:
      return "CDR2_BE, XCDR2";
    case 0x0007:
      return "CDR2_LE, XCDR2";
    case 0x0008:
      return "D_CDR2_BE, delimited XCDR2";
    case 0x0009:
      return "D_CDR2_LE, delimited XCDR2";
    case 0x000a:
      return "PL_CDR2_BE, parameter-list XCDR2";
    case 0x000b:
      return "PL_CDR2_LE, parameter-list XCDR2";
    default:
      return "unknown";
  }
}

constexpr std::array<std::uint8_t, 4> kCdrLeHeader{0x00, 0x01, 0x00, 0x00};

}  // namespace

// ---- CdrReader ----

CdrReader::CdrReader(std::span<const std::uint8_t> bytes, std::string_view what)
    : bytes_(bytes), what_(what) {
  if (bytes_.size() < kHeaderBytes) {
    throw Ros2Error(
        fmt::format("{} of {} bytes is shorter than the 4-byte CDR encapsulation header", what_,
                    bytes_.size()));
  }
  // The identifier is big-endian whatever the data's byte order (DDS-RTPS 2.5 section 10).
  const auto id = static_cast<std::uint16_t>(bytes_[0] << 8 | bytes_[1]);
  if (id != kCdrBe && id != kCdrLe) {
    throw Ros2Error(fmt::format(
        "{}: CDR encapsulation 0x{:04x} ({}) is not supported: ROS 2 messages are plain CDR "
        "(CDR_BE 0x0000 or CDR_LE 0x0001)",
        what_, id, encapsulationName(id)));
  }
  big_endian_ = id == kCdrBe;
}

void CdrReader::endsInside(const char* field, std::size_t needed) const {
  throw Ros2Error(
      fmt::format("{} of {} bytes ends inside its {} ({} bytes needed at offset {}, {} left)",
                  what_, bytes_.size(), field, needed, offset(), remaining()));
}

const std::uint8_t* CdrReader::take(const char* field, std::size_t count) {
  if (count > remaining()) endsInside(field, count);
  const std::uint8_t* at = bytes_.data() + pos_;
  pos_ += count;
  return at;
}

const std::uint8_t* CdrReader::primitive(const char* field, std::size_t size) {
  // Alignment is relative to the end of the encapsulation header, not to the buffer.
  const std::size_t padding = (size - offset() % size) % size;
  if (padding + size > remaining()) endsInside(field, padding + size);
  pos_ += padding;
  return take(field, size);
}

std::uint64_t CdrReader::unsignedOf(const std::uint8_t* p, std::size_t size) const {
  std::uint64_t value = 0;
  for (std::size_t i = 0; i < size; ++i) {
    const std::size_t byte = big_endian_ ? size - 1 - i : i;
    value |= std::uint64_t{p[byte]} << (8 * i);
  }
  return value;
}

std::uint8_t CdrReader::u8(const char* field) {
  return *primitive(field, 1);
}

std::int8_t CdrReader::i8(const char* field) {
  return std::bit_cast<std::int8_t>(u8(field));
}

std::uint16_t CdrReader::u16(const char* field) {
  return static_cast<std::uint16_t>(unsignedOf(primitive(field, 2), 2));
}

std::uint32_t CdrReader::u32(const char* field) {
  return static_cast<std::uint32_t>(unsignedOf(primitive(field, 4), 4));
}

std::int32_t CdrReader::i32(const char* field) {
  return std::bit_cast<std::int32_t>(u32(field));
}

double CdrReader::f64(const char* field) {
  return std::bit_cast<double>(unsignedOf(primitive(field, 8), 8));
}

bool CdrReader::boolean(const char* field) {
  // CDR encodes TRUE as 1 and FALSE as 0 (CORBA 3.3 part 2, 9.3 "CDR Transfer Syntax"); Fast CDR
  // refuses other bytes too.
  const std::uint8_t value = u8(field);
  if (value > 1) fail(fmt::format("its {} is byte {}, not a bool (0 or 1)", field, value));
  return value == 1;
}

std::string CdrReader::string(const char* field) {
  const std::uint32_t length = u32(field);
  if (length == 0) return {};
  if (length > remaining()) {
    throw Ros2Error(
        fmt::format("{} of {} bytes: its {} states a string of {} bytes where {} are left", what_,
                    bytes_.size(), field, length, remaining()));
  }
  const std::uint8_t* chars = take(field, length);
  if (chars[length - 1] != 0) {
    fail(fmt::format("its {} ({} bytes) does not end in a NUL", field, length));
  }
  return {reinterpret_cast<const char*>(chars), length - 1};
}

std::size_t CdrReader::sequenceLength(const char* field, std::size_t min_element_bytes) {
  const std::uint32_t count = u32(field);
  const std::size_t least = std::max<std::size_t>(min_element_bytes, 1);
  // Divided, not multiplied: the product could overflow on a 32-bit size_t.
  if (count > remaining() / least) {
    throw Ros2Error(fmt::format(
        "{} of {} bytes: its {} states {} elements of at least {} bytes where {} bytes are left",
        what_, bytes_.size(), field, count, least, remaining()));
  }
  return count;
}

void CdrReader::f64s(const char* field, std::span<double> out) {
  // Element by element: the first aligns to 8, and no elements (an empty float64[]) align nothing,
  // as Fast CDR's deserializeArray has it.
  for (double& value : out) value = f64(field);
}

std::vector<double> CdrReader::f64Sequence(const char* field) {
  std::vector<double> out(sequenceLength(field, sizeof(double)));
  f64s(field, out);
  return out;
}

std::span<const std::uint8_t> CdrReader::bytes(const char* field, std::size_t count) {
  return {take(field, count), count};
}

std::vector<std::uint8_t> CdrReader::u8Sequence(const char* field) {
  const std::span<const std::uint8_t> octets = bytes(field, sequenceLength(field, 1));
  return {octets.begin(), octets.end()};
}

void CdrReader::expectEnd() const {
  // Up to 3 bytes may pad the data to a multiple of 4 (RTPS pads serialised payloads so, and a
  // recorder may keep that padding).
  if (remaining() > 3) {
    throw Ros2Error(fmt::format("{} bytes left after the last field: not a {} (data of {} bytes)",
                                remaining(), what_, bytes_.size()));
  }
}

void CdrReader::fail(std::string_view message) const {
  throw Ros2Error(fmt::format("{}: {}", what_, message));
}

// ---- CdrWriter ----

CdrWriter::CdrWriter() : buffer_(kCdrLeHeader.begin(), kCdrLeHeader.end()) {}

void CdrWriter::align(std::size_t size) {
  while ((buffer_.size() - kCdrLeHeader.size()) % size != 0) buffer_.push_back(0);
}

void CdrWriter::littleEndian(std::uint64_t value, std::size_t size) {
  align(size);
  for (std::size_t i = 0; i < size; ++i) {
    buffer_.push_back(static_cast<std::uint8_t>(value >> (8 * i)));
  }
}

void CdrWriter::u8(std::uint8_t value) {
  buffer_.push_back(value);
}
void CdrWriter::i8(std::int8_t value) {
  u8(std::bit_cast<std::uint8_t>(value));
}
void CdrWriter::u16(std::uint16_t value) {
  littleEndian(value, 2);
}
void CdrWriter::u32(std::uint32_t value) {
  littleEndian(value, 4);
}
void CdrWriter::i32(std::int32_t value) {
  u32(std::bit_cast<std::uint32_t>(value));
}
void CdrWriter::f64(double value) {
  littleEndian(std::bit_cast<std::uint64_t>(value), 8);
}
void CdrWriter::boolean(bool value) {
  u8(value ? 1 : 0);
}

void CdrWriter::string(std::string_view value) {
  if (value.size() >= std::numeric_limits<std::uint32_t>::max()) {
    throw Ros2Error(fmt::format("a string of {} bytes is too long for CDR", value.size()));
  }
  u32(static_cast<std::uint32_t>(value.size() + 1));  // the length counts the NUL
  buffer_.insert(buffer_.end(), value.begin(), value.end());
  buffer_.push_back(0);
}

void CdrWriter::sequenceLength(std::size_t count) {
  if (count > std::numeric_limits<std::uint32_t>::max()) {
    throw Ros2Error(fmt::format("a sequence of {} elements is too long for CDR", count));
  }
  u32(static_cast<std::uint32_t>(count));
}

void CdrWriter::f64s(std::span<const double> values) {
  for (const double value : values) f64(value);
}

void CdrWriter::f64Sequence(std::span<const double> values) {
  sequenceLength(values.size());
  f64s(values);
}

void CdrWriter::bytes(std::span<const std::uint8_t> values) {
  buffer_.insert(buffer_.end(), values.begin(), values.end());
}

void CdrWriter::u8Sequence(std::span<const std::uint8_t> values) {
  sequenceLength(values.size());
  bytes(values);
}

std::vector<std::uint8_t> CdrWriter::take() {
  std::vector<std::uint8_t> message = std::move(buffer_);
  buffer_.assign(kCdrLeHeader.begin(), kCdrLeHeader.end());
  return message;
}

}  // namespace gvio::io::ros2
