#include "io/rosbag_dataset.hpp"

#include "io/bag_dataset.hpp"
#include "io/bag_source.hpp"
#include "io/input_error.hpp"
#include "io/rosbag/bag_file.hpp"
#include "io/text.hpp"

namespace gvio::io {
namespace {
namespace fs = std::filesystem;

// librosbag_storage's reader offers what the dataset reader asks for, as it is.
class Ros1Source final : public BagSource {
 public:
  explicit Ros1Source(const fs::path& file) : reader_(file.string()) {}
  std::vector<bag::TopicInfo> topics() const override { return reader_.topics(); }
  std::vector<bag::ImuMessage> readImu(const std::string& topic) const override {
    return reader_.readImu(topic);
  }
  std::vector<bag::NavSatFixMessage> readNavSatFix(const std::string& topic) const override {
    return reader_.readNavSatFix(topic);
  }
  std::vector<bag::Stamps> imageStamps(const std::string& topic) const override {
    return reader_.imageStamps(topic);
  }
  bag::ImageMessage readImage(const std::string& topic, std::size_t index) const override {
    return reader_.readImage(topic, index);
  }

 private:
  bag::BagReader reader_;
};

}  // namespace

bool looksLikeRosbag(const fs::path& file) {
  return fileStartsWith(file, "#ROSBAG V");
}

Dataset readRosbag(const fs::path& file, const ReaderConfig& config) {
  Dataset ds;
  ds.format = DatasetFormat::kRosbag;
  ds.root = file;
  ds.variant = "bag";
  std::shared_ptr<const BagSource> source;
  try {
    if (!looksLikeRosbag(file)) throw bag::BagError("not a ROS bag (no '#ROSBAG V' magic)");
    source = std::make_shared<const Ros1Source>(file);
  } catch (const bag::BagError& e) {
    throw InputError(file, 0, e.what());
  }
  readBagDataset(file, source, config, ds);
  return ds;
}

}  // namespace gvio::io
