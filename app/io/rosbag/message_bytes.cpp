#include "io/rosbag/message_bytes.hpp"

#include <string>

#include "io/rosbag/bag_file.hpp"
#include "io/rosbag/little_endian.hpp"

namespace gvio::io::bag {

namespace {

// Serialised fields read in order; every step is checked against the bytes left.
class FieldCursor {
 public:
  explicit FieldCursor(const std::vector<std::uint8_t>& bytes) : bytes_(bytes) {}

  void skip(std::size_t count, const char* field) {
    if (count > left()) {
      throw BagError("message of " + std::to_string(bytes_.size()) + " bytes ends inside its " +
                     field);
    }
    pos_ += count;
  }

  std::uint32_t u32(const char* field) {
    const std::size_t at = pos_;
    skip(4, field);
    return littleEndian32(&bytes_[at]);
  }

  // A string or uint8[]: its u32 length, then that many bytes.
  void skipSized(const char* field) { skip(u32(field), field); }

  // std_msgs/Header: seq (u32), stamp (2 x u32), frame_id (string).
  void skipHeader() {
    skip(12, "header");
    skipSized("header's frame_id");
  }

  // The trailing uint8[] data: its stated length must not exceed what follows.
  void checkData() {
    const std::uint32_t stated = u32("data length");
    if (stated > left()) {
      throw BagError("image data of " + std::to_string(stated) + " bytes stated in a message of " +
                     std::to_string(bytes_.size()) + " bytes");
    }
  }

 private:
  std::size_t left() const { return bytes_.size() - pos_; }

  const std::vector<std::uint8_t>& bytes_;
  std::size_t pos_ = 0;
};

}  // namespace

void checkImageBytes(const std::vector<std::uint8_t>& bytes) {
  FieldCursor cursor(bytes);
  cursor.skipHeader();
  cursor.skip(8, "height and width");
  cursor.skipSized("encoding");
  cursor.skip(5, "is_bigendian and step");
  cursor.checkData();
}

void checkCompressedImageBytes(const std::vector<std::uint8_t>& bytes) {
  FieldCursor cursor(bytes);
  cursor.skipHeader();
  cursor.skipSized("format");
  cursor.checkData();
}

}  // namespace gvio::io::bag
