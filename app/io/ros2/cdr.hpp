#pragma once
// CDR, the serialisation of ROS 2 messages (rmw_fastrtps, rmw_cyclonedds: encoding version 1,
// "plain CDR": OMG CORBA 3.3 part 2 section 9.3 "CDR Transfer Syntax", as DDS-XTypes 1.3 section
// 7.4 calls XCDR1; the encapsulation identifiers are DDS-RTPS 2.5 section 10's). A serialised
// message is a 4-byte encapsulation header (identifier, a big-endian u16, then 2 option bytes)
// followed by the fields in declaration order:
//  - every primitive is aligned to its own size (1, 2, 4 or 8 bytes), counted from the first
//    byte after the encapsulation header (the padding bytes are written as zeros, read as any);
//  - bool is one byte, 0 or 1;
//  - a string is a u32 length that counts the terminating NUL, the characters and the NUL;
//  - a sequence (T[]) is a u32 element count, then the elements; a fixed array (T[N]) the
//    elements only; a nested struct is its fields, with no alignment of its own.
// CdrReader reads a message defensively (bytes from a bag are untrusted: every read is checked
// against the bytes left, and a stated length is checked before anything is allocated for it);
// CdrWriter writes one, little-endian.
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace gvio::io::ros2 {

class CdrReader {
 public:
  // Reads the encapsulation header. Throws Ros2Error for fewer than 4 bytes, for parameter-list
  // CDR (PL_CDR_BE/LE, 0x0002/0x0003) or XCDR2, and any other identifier than CDR_BE (0x0000) or
  // CDR_LE (0x0001). The option bytes are ignored. `what` names the data in error messages (a
  // message type, e.g. "sensor_msgs/msg/Imu"). The bytes and `what` must outlive the reader.
  explicit CdrReader(std::span<const std::uint8_t> bytes, std::string_view what = "CDR data");

  [[nodiscard]] bool bigEndian() const { return big_endian_; }
  // Position counted from the first byte after the encapsulation header, and the bytes after it.
  [[nodiscard]] std::size_t offset() const { return pos_ - kHeaderBytes; }
  [[nodiscard]] std::size_t remaining() const { return bytes_.size() - pos_; }

  // Each read aligns, then reads; `field` names the field in the Ros2Error thrown when the data
  // ends inside it.
  std::int8_t i8(const char* field);
  std::uint8_t u8(const char* field);
  std::uint16_t u16(const char* field);
  std::int32_t i32(const char* field);
  std::uint32_t u32(const char* field);
  double f64(const char* field);    // bit for bit: NaN payloads and infinities are kept
  bool boolean(const char* field);  // a byte other than 0 or 1 is a defect
  // A u32 length counting the NUL, then the characters and the NUL (a missing NUL is a defect).
  // Length 0 (no NUL at all) is read as "", as Fast CDR does.
  std::string string(const char* field);
  // A sequence's u32 element count, checked against the bytes left: `min_element_bytes` is the
  // least one element occupies (at least 1), so the count times it must fit in what follows.
  std::size_t sequenceLength(const char* field, std::size_t min_element_bytes);
  // float64[N]: `out.size()` doubles. float64[]: a counted sequence of them.
  void f64s(const char* field, std::span<double> out);
  template <std::size_t N>
  std::array<double, N> f64Array(const char* field) {
    std::array<double, N> out{};
    f64s(field, out);
    return out;
  }
  std::vector<double> f64Sequence(const char* field);
  // `count` bytes as they are (octets need no alignment); uint8[]: a counted sequence of them.
  std::span<const std::uint8_t> bytes(const char* field, std::size_t count);
  std::vector<std::uint8_t> u8Sequence(const char* field);

  // Throws unless the last field ended the data: more than 3 bytes left over (more than the
  // padding to a 4-byte boundary some writers append) means the data is not what the reader was
  // told it is (`what`), e.g. a message of another type recorded under this one's name.
  void expectEnd() const;
  // Throws Ros2Error with `message` prefixed by what the data is: for a value the type forbids.
  [[noreturn]] void fail(std::string_view message) const;

 private:
  static constexpr std::size_t kHeaderBytes = 4;

  // Skips the padding to a multiple of `size`, then returns the next `size` bytes.
  const std::uint8_t* primitive(const char* field, std::size_t size);
  const std::uint8_t* take(const char* field, std::size_t count);
  std::uint64_t unsignedOf(const std::uint8_t* p, std::size_t size) const;
  [[noreturn]] void endsInside(const char* field, std::size_t needed) const;

  std::span<const std::uint8_t> bytes_;
  std::string_view what_;
  std::size_t pos_ = kHeaderBytes;
  bool big_endian_ = false;
};

class CdrWriter {
 public:
  CdrWriter();  // writes the encapsulation header of CDR_LE: 00 01 00 00

  void i8(std::int8_t value);
  void u8(std::uint8_t value);
  void u16(std::uint16_t value);
  void i32(std::int32_t value);
  void u32(std::uint32_t value);
  void f64(double value);
  void boolean(bool value);
  void string(std::string_view value);        // throws Ros2Error when its length overflows the u32
  void sequenceLength(std::size_t count);     // likewise
  void f64s(std::span<const double> values);  // float64[N]: the elements only
  void f64Sequence(std::span<const double> values);
  void bytes(std::span<const std::uint8_t> values);  // octets only
  void u8Sequence(std::span<const std::uint8_t> values);

  // The message; the writer then starts a new one (with its own encapsulation header).
  [[nodiscard]] std::vector<std::uint8_t> take();

 private:
  void align(std::size_t size);
  void littleEndian(std::uint64_t value, std::size_t size);

  std::vector<std::uint8_t> buffer_;
};

}  // namespace gvio::io::ros2
