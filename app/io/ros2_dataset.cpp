#include "io/ros2_dataset.hpp"

#include <fmt/format.h>

#include "io/bag_dataset.hpp"
#include "io/bag_source.hpp"
#include "io/input_error.hpp"
#include "io/ros2/bag_calibration.hpp"
#include "io/ros2/ros2_bag.hpp"
#include "io/ros2/ros2_error.hpp"
#include "io/ros2/ros2_messages.hpp"

namespace gvio::io {
namespace {
namespace fs = std::filesystem;
using ros2::Ros2Bag;
using ros2::Ros2Error;
using ros2::Ros2Topic;

// Every message of t decoded, stamped with its receive time (the bag's log time).
template <typename Decode>
auto readAll(const Ros2Bag& bag, const Ros2Topic& t, Decode decode) {
  std::vector<decltype(ros2::decodeMessage(bag, t, 0, decode))> out;
  for (std::size_t i = 0; i < t.messages.size(); ++i) {
    out.push_back(ros2::decodeMessage(bag, t, i, decode));
    out.back().t.receive_ns = bag.logTimeNs(t, i);
  }
  return out;
}

// A ROS 2 bag's messages decoded from CDR into what the bag dataset reader takes; the receive
// time is the bag's log time.
class Ros2Source final : public BagSource {
 public:
  explicit Ros2Source(std::shared_ptr<const Ros2Bag> bag) : bag_(std::move(bag)) {}

  std::vector<bag::TopicInfo> topics() const override {
    std::vector<bag::TopicInfo> out;
    for (const Ros2Topic& t : bag_->topics()) {
      out.push_back({t.name, ros2::ros1TypeName(t.type), t.messages.size()});
    }
    return out;
  }

  std::vector<bag::ImuMessage> readImu(const std::string& name) const override {
    return readAll(*bag_, topic(name, ros2::kRos2ImuType),
                   [](const auto& bytes) { return ros2::decodeImu(bytes).imu; });
  }

  std::vector<bag::NavSatFixMessage> readNavSatFix(const std::string& name) const override {
    return readAll(*bag_, topic(name, ros2::kRos2NavSatFixType),
                   [](const auto& bytes) { return ros2::decodeNavSatFix(bytes).fix; });
  }

  std::vector<bag::Stamps> imageStamps(const std::string& name) const override {
    const Ros2Topic& t = imageTopic(name);
    std::vector<bag::Stamps> out;
    out.reserve(t.messages.size());
    for (std::size_t i = 0; i < t.messages.size(); ++i) {
      try {
        out.push_back({bag_->headerStampNs(t, i), bag_->logTimeNs(t, i)});
      } catch (const Ros2Error& e) {
        throw Ros2Error(fmt::format("topic {}: message {}: {}", name, i, e.what()));
      }
    }
    return out;
  }

  bag::ImageMessage readImage(const std::string& name, std::size_t index) const override {
    const Ros2Topic& t = imageTopic(name);
    const bool compressed = t.type == ros2::kRos2CompressedImageType;
    bag::ImageMessage m = ros2::decodeMessage(*bag_, t, index, [&](const auto& bytes) {
      return compressed ? ros2::decodeCompressedImage(bytes).image : ros2::decodeImage(bytes).image;
    });
    m.t.receive_ns = bag_->logTimeNs(t, index);
    return m;
  }

 private:
  const Ros2Topic& topic(const std::string& name, const char* type) const {
    const Ros2Topic* t = bag_->topic(name);
    if (t == nullptr) throw Ros2Error(fmt::format("no topic {} in the bag", name));
    if (t->type != type)
      throw Ros2Error(fmt::format("topic {} is {}, not {}", name, t->type, type));
    if (t->serialization_format != "cdr") {
      throw Ros2Error(fmt::format("topic {} is serialised as '{}': gvio reads cdr", name,
                                  t->serialization_format));
    }
    return *t;
  }

  const Ros2Topic& imageTopic(const std::string& name) const {
    const Ros2Topic* t = bag_->topic(name);
    const bool compressed = t != nullptr && t->type == ros2::kRos2CompressedImageType;
    return topic(name, compressed ? ros2::kRos2CompressedImageType : ros2::kRos2ImageType);
  }

  std::shared_ptr<const Ros2Bag> bag_;
};

}  // namespace

Dataset readRos2Bag(const fs::path& path, const ReaderConfig& config) {
  Dataset ds;
  ds.format = DatasetFormat::kRos2Bag;
  ds.root = path;
  const auto bag = std::make_shared<const Ros2Bag>(path);
  ds.variant = fmt::format("ROS 2 bag, {}", bag->storage());
  for (const std::string& w : bag->warnings()) ds.warnings.push_back(w);
  readBagDataset(path, std::make_shared<const Ros2Source>(bag), config, ds);
  try {
    ros2::applyBagCalibration(*bag, ds);
  } catch (const Ros2Error& e) {
    throw InputError(path, 0, e.what());
  }
  return ds;
}

}  // namespace gvio::io
