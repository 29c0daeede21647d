#pragma once
// One storage file of a ROS 2 bag (an .mcap or a .db3), as the bag reader sees it: its topics, its
// messages in storage order, and each message's serialised bytes on request. rosbag2 splits a
// recording into several such files (metadata.yaml lists them); Ros2Bag joins them.
#include <array>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

namespace gvio::io::ros2 {

struct StoredTopic {
  std::string name;
  std::string type;                  // ROS 2 form, e.g. sensor_msgs/msg/Image
  std::string serialization_format;  // "cdr" for every rmw in use
};

struct StoredMessage {
  std::size_t topic = 0;         // index into topics()
  std::int64_t log_time_ns = 0;  // the recorder's receive time
};

// A message's first bytes: enough for the CDR encapsulation and a std_msgs/Header's stamp.
struct MessageHead {
  std::array<std::uint8_t, 16> bytes{};
  std::size_t size = 0;
};

class StorageFile {
 public:
  virtual ~StorageFile() = default;
  [[nodiscard]] virtual const std::vector<StoredTopic>& topics() const = 0;
  [[nodiscard]] virtual const std::vector<StoredMessage>& messages() const = 0;
  // Message i's bytes (all of them, or only the head). Safe to call from several threads. Throws
  // Ros2Error.
  [[nodiscard]] virtual std::vector<std::uint8_t> read(std::size_t message) const = 0;
  [[nodiscard]] virtual MessageHead head(std::size_t message) const = 0;
  // Defects the file could be read past (e.g. an MCAP file cut short), one line each.
  [[nodiscard]] virtual std::vector<std::string> warnings() const = 0;
};

// Open by content: MCAP's magic or SQLite's header. Throws Ros2Error for anything else.
std::unique_ptr<StorageFile> openStorageFile(const std::filesystem::path& file);
bool looksLikeMcap(const std::filesystem::path& file);
bool looksLikeSqlite(const std::filesystem::path& file);

}  // namespace gvio::io::ros2
