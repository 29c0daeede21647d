#pragma once
// ROS1 bags through Debian's librosbag_storage, with no ROS installation (no roscore, no
// environment variables). Only this layer sees ROS headers: the generated message headers use
// std::allocator<void>::rebind, which C++20 removed, so it is built as C++17 (target gvio_bag) and
// its interface holds standard types only. Reading and writing; bags stay on disk (images are read
// one message at a time).
#include <array>
#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace gvio::io::bag {

// Any failure opening, reading or writing a bag, with what went wrong; callers add the file name.
class BagError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct TopicInfo {
  std::string name;
  std::string datatype;  // e.g. sensor_msgs/Image
  std::uint64_t messages = 0;
};

// Times of one message: the sensor's (header.stamp) and the recorder's (bag time).
struct Stamps {
  std::int64_t header_ns = 0;
  std::int64_t receive_ns = 0;
};

struct ImuMessage {
  Stamps t;
  std::array<double, 3> acc_mps2{};
  std::array<double, 3> gyr_radps{};
  // The attitude the IMU reports (REP 145: the body's rotation from ENU) and its covariance
  // (row major, rad^2, about x y z); element 0 = -1: no orientation (sensor_msgs/Imu).
  std::array<double, 4> orientation_xyzw{0.0, 0.0, 0.0, 1.0};
  std::array<double, 9> orientation_covariance{-1.0};
};

// sensor_msgs/NavSatFix: status -1 no fix, 0 fix, 1 SBAS, 2 GBAS; altitude above the WGS84
// ellipsoid; position_covariance in ENU (m^2, row major) with its type (0 unknown, 1 approximated,
// 2 diagonal known, 3 known).
struct NavSatFixMessage {
  Stamps t;
  int status = -1;
  double lat_deg = 0.0, lon_deg = 0.0, alt_m = 0.0;
  std::array<double, 9> covariance_enu_m2{};
  int covariance_type = 0;
};

// sensor_msgs/Image (compressed = false: encoding, size, step, pixels) or
// sensor_msgs/CompressedImage (compressed = true: format and the encoded bytes).
struct ImageMessage {
  Stamps t;
  bool compressed = false;
  std::string encoding;  // Image
  std::uint32_t width = 0, height = 0, step = 0;
  bool big_endian = false;
  std::string format;  // CompressedImage, e.g. "png", "jpeg", "mono8; jpeg compressed mono8"
  std::vector<std::uint8_t> data;
};

inline constexpr const char* kImageType = "sensor_msgs/Image";
inline constexpr const char* kCompressedImageType = "sensor_msgs/CompressedImage";
inline constexpr const char* kImuType = "sensor_msgs/Imu";
inline constexpr const char* kNavSatFixType = "sensor_msgs/NavSatFix";

class BagReader {
 public:
  // Opens and indexes the bag (its index records only: messages are read on demand). Throws
  // BagError for a missing, unindexed, truncated or otherwise unreadable bag.
  explicit BagReader(const std::string& path);
  ~BagReader();
  BagReader(const BagReader&) = delete;
  BagReader& operator=(const BagReader&) = delete;

  [[nodiscard]] std::vector<TopicInfo> topics() const;
  // Every message of the topic, in bag order. Throws BagError when the topic has another type or
  // a message cannot be read.
  [[nodiscard]] std::vector<ImuMessage> readImu(const std::string& topic) const;
  [[nodiscard]] std::vector<NavSatFixMessage> readNavSatFix(const std::string& topic) const;
  // The stamps of an image topic's messages (Image or CompressedImage), in bag order; message i of
  // that order is then read by readImage(topic, i). Reading the stamps decodes headers only.
  [[nodiscard]] std::vector<Stamps> imageStamps(const std::string& topic) const;
  // Safe to call from several threads (reads are serialised: the bag caches one chunk).
  [[nodiscard]] ImageMessage readImage(const std::string& topic, std::size_t index) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

enum class Compression { kNone, kBz2, kLz4 };

class BagWriter {
 public:
  BagWriter(const std::string& path, Compression compression);  // throws BagError
  ~BagWriter();
  BagWriter(const BagWriter&) = delete;
  BagWriter& operator=(const BagWriter&) = delete;

  // Each message is stamped in the bag with its receive time.
  void write(const std::string& topic, const ImuMessage& message);
  void write(const std::string& topic, const NavSatFixMessage& message);
  void write(const std::string& topic, const ImageMessage& message);
  void close();  // flushes the index; throws BagError

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace gvio::io::bag
