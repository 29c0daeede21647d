#pragma once
// A ROS 2 bag as one recording: a bag folder (metadata.yaml and its storage files, split bags
// included; without metadata.yaml, every .mcap/.db3 file of the folder in name order, as
// `ros2 bag reindex` would list them), or one .mcap or .db3 file. Topics are joined across the
// files by name; each topic's messages keep storage order (file by file). Messages compressed one
// by one (compression_mode MESSAGE, zstd) are decompressed on reading.
#include <cstdint>
#include <filesystem>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "io/ros2/ros2_error.hpp"
#include "io/ros2/storage.hpp"

namespace gvio::io::ros2 {

struct Ros2Topic {
  std::string name;
  std::string type;  // ROS 2 form
  std::string serialization_format;
  struct Ref {
    std::size_t file = 0;     // index into files()
    std::size_t message = 0;  // index into that file's messages
  };
  std::vector<Ref> messages;
};

class Ros2Bag {
 public:
  // Throws InputError naming the folder, metadata.yaml or the storage file at fault: a file
  // metadata.yaml lists that is missing, a storage plugin other than mcap or sqlite3, whole-file
  // compression, a topic whose type differs between files, a damaged file.
  explicit Ros2Bag(const std::filesystem::path& path);

  [[nodiscard]] const std::vector<Ros2Topic>& topics() const { return topics_; }
  [[nodiscard]] const Ros2Topic* topic(const std::string& name) const;
  [[nodiscard]] const std::vector<std::filesystem::path>& files() const { return files_; }
  [[nodiscard]] const std::string& storage() const { return storage_; }  // mcap, sqlite3, mixed
  // Defects the storage files could be read past, each naming its file.
  [[nodiscard]] const std::vector<std::string>& warnings() const { return warnings_; }

  // Message `index` of `topic` (in its storage order). Thread-safe. Throws Ros2Error.
  [[nodiscard]] std::vector<std::uint8_t> read(const Ros2Topic& topic, std::size_t index) const;
  [[nodiscard]] std::int64_t logTimeNs(const Ros2Topic& topic, std::size_t index) const;
  // The header stamp of a message that starts with std_msgs/Header, without reading all of it.
  [[nodiscard]] std::int64_t headerStampNs(const Ros2Topic& topic, std::size_t index) const;

 private:
  void open(const std::filesystem::path& file);

  std::vector<std::filesystem::path> files_;
  std::vector<std::unique_ptr<StorageFile>> storages_;
  std::vector<Ros2Topic> topics_;
  std::vector<std::string> warnings_;
  std::string storage_;
  bool message_compression_ = false;  // zstd per message
};

// Message `index` of `topic` decoded by `decode` (a function of the message's bytes); a defect is
// a Ros2Error naming the topic and the message.
template <typename Decode>
auto decodeMessage(const Ros2Bag& bag, const Ros2Topic& topic, std::size_t index, Decode decode) {
  try {
    const std::vector<std::uint8_t> bytes = bag.read(topic, index);
    return decode(std::span<const std::uint8_t>(bytes));
  } catch (const Ros2Error& e) {
    throw Ros2Error("topic " + topic.name + ": message " + std::to_string(index) + ": " + e.what());
  }
}

// A bag folder with metadata.yaml, or a file with MCAP's magic or SQLite's header.
bool looksLikeRos2Bag(const std::filesystem::path& path);

}  // namespace gvio::io::ros2
