#include "io/rosbag/bag_file.hpp"

#include "io/rosbag/message_bytes.hpp"
#include "io/rosbag/record_scan.hpp"

#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/CompressedImage.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/Imu.h>
#include <sensor_msgs/NavSatFix.h>

#include <boost/make_shared.hpp>
#include <map>
#include <mutex>

// A message type that reads only the std_msgs/Header every stamped message starts with: the
// frame list needs the stamps of all images, not their pixels. Its MD5 "*" matches any type.
namespace gvio::io::bag {
struct HeaderOnly {
  std_msgs::Header header;
};
}  // namespace gvio::io::bag

namespace ros::message_traits {
template <>
struct MD5Sum<gvio::io::bag::HeaderOnly> {
  static const char* value() { return "*"; }
  static const char* value(const gvio::io::bag::HeaderOnly&) { return value(); }
};
template <>
struct DataType<gvio::io::bag::HeaderOnly> {
  static const char* value() { return "*"; }
  static const char* value(const gvio::io::bag::HeaderOnly&) { return value(); }
};
template <>
struct Definition<gvio::io::bag::HeaderOnly> {
  static const char* value() { return ""; }
  static const char* value(const gvio::io::bag::HeaderOnly&) { return value(); }
};
}  // namespace ros::message_traits

namespace ros::serialization {
template <>
struct Serializer<gvio::io::bag::HeaderOnly> {
  template <typename Stream>
  static void read(Stream& stream, gvio::io::bag::HeaderOnly& m) {
    stream.next(m.header);
  }
};
}  // namespace ros::serialization

namespace gvio::io::bag {
namespace {

std::int64_t nanoseconds(const ros::Time& t) {
  return static_cast<std::int64_t>(t.toNSec());
}

ros::Time rosTime(std::int64_t t_ns) {
  if (t_ns < 0) throw BagError("a ROS time cannot be negative (" + std::to_string(t_ns) + " ns)");
  ros::Time t;
  t.fromNSec(static_cast<std::uint64_t>(t_ns));
  return t;
}

Stamps stampsOf(const std_msgs::Header& header, const rosbag::MessageInstance& m) {
  return {nanoseconds(header.stamp), nanoseconds(m.getTime())};
}

std_msgs::Header headerOf(const Stamps& t) {
  std_msgs::Header h;
  h.stamp = rosTime(t.header_ns);
  return h;
}

// Runs f, turning whatever librosbag or the ROS deserialiser throws into BagError.
template <typename F>
auto guarded(const std::string& what, F&& f) -> decltype(f()) {
  try {
    return f();
  } catch (const BagError&) {
    throw;
  } catch (const rosbag::BagUnindexedException&) {
    throw BagError("unindexed bag (the recording was interrupted?): run 'rosbag reindex' on it");
  } catch (const std::exception& e) {
    throw BagError(what + ": " + e.what());
  }
}

// A message whose connection's md5sum is not that of the type gvio reads it as (a damaged record
// or another definition under the same type name). The md5sum itself is not quoted: it is the
// bag's bytes. The type name is the bag's text too; InputError, which every BagError becomes,
// escapes its control bytes so that the message stays one line.
[[noreturn]] void unexpectedType(const rosbag::MessageInstance& m) {
  throw BagError("message of unexpected type " + m.getDataType() +
                 " (its md5sum is not that of the definition gvio reads)");
}

// The message as T: MessageInstance::instantiate gives null for another md5sum, which is an error
// of the bag, never a null to dereference.
template <typename T>
boost::shared_ptr<T> instantiated(const rosbag::MessageInstance& m) {
  boost::shared_ptr<T> msg = m.instantiate<T>();
  if (!msg) unexpectedType(m);
  return msg;
}

// An image message as T from its bytes, which `check` (message_bytes.hpp) clears first: ROS's
// deserialiser allocates whatever length a uint8[] states before it reads the bytes.
template <typename T>
boost::shared_ptr<T> checkedImage(const rosbag::MessageInstance& m,
                                  void (*check)(const std::vector<std::uint8_t>&)) {
  if (!m.isType<T>()) unexpectedType(m);
  std::vector<std::uint8_t> bytes(m.size());
  ros::serialization::OStream out(bytes.data(), static_cast<std::uint32_t>(bytes.size()));
  m.write(out);
  check(bytes);
  auto msg = boost::make_shared<T>();
  ros::serialization::IStream in(bytes.data(), static_cast<std::uint32_t>(bytes.size()));
  ros::serialization::deserialize(in, *msg);
  return msg;
}

}  // namespace

struct BagReader::Impl {
  rosbag::Bag bag;
  std::map<std::string, std::string> types;  // topic -> datatype
  mutable std::mutex mutex;                  // rosbag::Bag caches the last chunk it decompressed
  mutable std::map<std::string, std::vector<rosbag::MessageInstance>> images;

  void requireType(const std::string& topic, const std::vector<std::string>& accepted) const {
    const auto it = types.find(topic);
    if (it == types.end()) throw BagError("no topic " + topic + " in the bag");
    for (const auto& a : accepted) {
      if (it->second == a) return;
    }
    std::string expected;
    for (const auto& a : accepted) expected += (expected.empty() ? "" : " or ") + a;
    throw BagError("topic " + topic + " is " + it->second + ", expected " + expected);
  }

  template <typename Msg, typename Out, typename Convert>
  std::vector<Out> readAll(const std::string& topic, const char* type, Convert convert) const {
    requireType(topic, {type});
    std::lock_guard<std::mutex> lock(mutex);
    return guarded("reading " + topic, [&] {
      std::vector<Out> out;
      rosbag::View view(bag, rosbag::TopicQuery(topic));
      out.reserve(view.size());
      for (const rosbag::MessageInstance& m : view) {
        out.push_back(convert(*instantiated<Msg>(m), m));
      }
      return out;
    });
  }
};

BagReader::BagReader(const std::string& path) : impl_(std::make_unique<Impl>()) {
  checkBagRecords(path);
  guarded("cannot read the bag (truncated or damaged?)", [&] {
    impl_->bag.open(path, rosbag::bagmode::Read);
    rosbag::View all(impl_->bag);
    for (const rosbag::ConnectionInfo* c : all.getConnections())
      impl_->types[c->topic] = c->datatype;
  });
}

BagReader::~BagReader() = default;

std::vector<TopicInfo> BagReader::topics() const {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  return guarded("reading the bag's index", [&] {
    std::vector<TopicInfo> out;
    for (const auto& [topic, type] : impl_->types) {
      rosbag::View view(impl_->bag, rosbag::TopicQuery(topic));
      out.push_back({topic, type, view.size()});
    }
    return out;
  });
}

std::vector<ImuMessage> BagReader::readImu(const std::string& topic) const {
  return impl_->readAll<sensor_msgs::Imu, ImuMessage>(
      topic, kImuType, [](const sensor_msgs::Imu& msg, const rosbag::MessageInstance& m) {
        ImuMessage out;
        out.t = stampsOf(msg.header, m);
        out.acc_mps2 = {msg.linear_acceleration.x, msg.linear_acceleration.y,
                        msg.linear_acceleration.z};
        out.gyr_radps = {msg.angular_velocity.x, msg.angular_velocity.y, msg.angular_velocity.z};
        out.orientation_xyzw = {msg.orientation.x, msg.orientation.y, msg.orientation.z,
                                msg.orientation.w};
        for (std::size_t i = 0; i < 9; ++i)
          out.orientation_covariance[i] = msg.orientation_covariance[i];
        return out;
      });
}

std::vector<NavSatFixMessage> BagReader::readNavSatFix(const std::string& topic) const {
  return impl_->readAll<sensor_msgs::NavSatFix, NavSatFixMessage>(
      topic, kNavSatFixType,
      [](const sensor_msgs::NavSatFix& msg, const rosbag::MessageInstance& m) {
        NavSatFixMessage out;
        out.t = stampsOf(msg.header, m);
        out.status = msg.status.status;
        out.lat_deg = msg.latitude;
        out.lon_deg = msg.longitude;
        out.alt_m = msg.altitude;
        for (std::size_t i = 0; i < 9; ++i) out.covariance_enu_m2[i] = msg.position_covariance[i];
        out.covariance_type = msg.position_covariance_type;
        return out;
      });
}

std::vector<Stamps> BagReader::imageStamps(const std::string& topic) const {
  impl_->requireType(topic, {kImageType, kCompressedImageType});
  std::lock_guard<std::mutex> lock(impl_->mutex);
  return guarded("reading " + topic, [&] {
    std::vector<Stamps> out;
    std::vector<rosbag::MessageInstance> instances;
    rosbag::View view(impl_->bag, rosbag::TopicQuery(topic));
    out.reserve(view.size());
    for (const rosbag::MessageInstance& m : view) {
      out.push_back(stampsOf(instantiated<HeaderOnly>(m)->header, m));
      instances.push_back(m);
    }
    impl_->images.erase(topic);
    impl_->images.emplace(topic, std::move(instances));
    return out;
  });
}

ImageMessage BagReader::readImage(const std::string& topic, std::size_t index) const {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  const auto it = impl_->images.find(topic);
  if (it == impl_->images.end() || index >= it->second.size()) {
    throw BagError("image " + std::to_string(index) + " of " + topic + " was not indexed");
  }
  const rosbag::MessageInstance& m = it->second[index];
  return guarded("reading image " + std::to_string(index) + " of " + topic, [&] {
    ImageMessage out;
    if (m.getDataType() == kCompressedImageType) {
      const auto msg = checkedImage<sensor_msgs::CompressedImage>(m, checkCompressedImageBytes);
      out.t = stampsOf(msg->header, m);
      out.compressed = true;
      out.format = msg->format;
      out.data = std::move(msg->data);
      return out;
    }
    const auto msg = checkedImage<sensor_msgs::Image>(m, checkImageBytes);
    out.t = stampsOf(msg->header, m);
    out.encoding = msg->encoding;
    out.width = msg->width;
    out.height = msg->height;
    out.step = msg->step;
    out.big_endian = msg->is_bigendian != 0;
    out.data = std::move(msg->data);
    return out;
  });
}

struct BagWriter::Impl {
  rosbag::Bag bag;
};

BagWriter::BagWriter(const std::string& path, Compression compression)
    : impl_(std::make_unique<Impl>()) {
  guarded("cannot write the bag", [&] {
    impl_->bag.open(path, rosbag::bagmode::Write);
    switch (compression) {
      case Compression::kNone:
        impl_->bag.setCompression(rosbag::compression::Uncompressed);
        break;
      case Compression::kBz2:
        impl_->bag.setCompression(rosbag::compression::BZ2);
        break;
      case Compression::kLz4:
        impl_->bag.setCompression(rosbag::compression::LZ4);
        break;
    }
  });
}

BagWriter::~BagWriter() {
  try {
    impl_->bag.close();
  } catch (...) {  // close() reports errors; a destructor must not throw
  }
}

void BagWriter::write(const std::string& topic, const ImuMessage& message) {
  sensor_msgs::Imu msg;
  msg.header = headerOf(message.t);
  msg.linear_acceleration.x = message.acc_mps2[0];
  msg.linear_acceleration.y = message.acc_mps2[1];
  msg.linear_acceleration.z = message.acc_mps2[2];
  msg.angular_velocity.x = message.gyr_radps[0];
  msg.angular_velocity.y = message.gyr_radps[1];
  msg.angular_velocity.z = message.gyr_radps[2];
  msg.orientation.x = message.orientation_xyzw[0];
  msg.orientation.y = message.orientation_xyzw[1];
  msg.orientation.z = message.orientation_xyzw[2];
  msg.orientation.w = message.orientation_xyzw[3];
  for (std::size_t i = 0; i < 9; ++i)
    msg.orientation_covariance[i] = message.orientation_covariance[i];
  guarded("writing " + topic, [&] { impl_->bag.write(topic, rosTime(message.t.receive_ns), msg); });
}

void BagWriter::write(const std::string& topic, const NavSatFixMessage& message) {
  sensor_msgs::NavSatFix msg;
  msg.header = headerOf(message.t);
  msg.status.status = static_cast<std::int8_t>(message.status);
  msg.status.service = sensor_msgs::NavSatStatus::SERVICE_GPS;
  msg.latitude = message.lat_deg;
  msg.longitude = message.lon_deg;
  msg.altitude = message.alt_m;
  for (std::size_t i = 0; i < 9; ++i) msg.position_covariance[i] = message.covariance_enu_m2[i];
  msg.position_covariance_type = static_cast<std::uint8_t>(message.covariance_type);
  guarded("writing " + topic, [&] { impl_->bag.write(topic, rosTime(message.t.receive_ns), msg); });
}

void BagWriter::write(const std::string& topic, const ImageMessage& message) {
  guarded("writing " + topic, [&] {
    if (message.compressed) {
      sensor_msgs::CompressedImage msg;
      msg.header = headerOf(message.t);
      msg.format = message.format;
      msg.data = message.data;
      impl_->bag.write(topic, rosTime(message.t.receive_ns), msg);
      return;
    }
    sensor_msgs::Image msg;
    msg.header = headerOf(message.t);
    msg.encoding = message.encoding;
    msg.width = message.width;
    msg.height = message.height;
    msg.step = message.step;
    msg.is_bigendian = message.big_endian ? 1 : 0;
    msg.data = message.data;
    impl_->bag.write(topic, rosTime(message.t.receive_ns), msg);
  });
}

void BagWriter::close() {
  guarded("closing the bag", [&] { impl_->bag.close(); });
}

}  // namespace gvio::io::bag
