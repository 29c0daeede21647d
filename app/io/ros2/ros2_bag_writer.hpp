#pragma once
// Writes a ROS 2 bag folder as `ros2 bag record` leaves one: <folder>/<name>_0.mcap (or .db3) and
// metadata.yaml, the messages already CDR-serialised (io/ros2/ros2_messages.hpp). MCAP channels
// carry their type's ros2msg definition (so other tools can decode them without ROS).
#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "io/ros2/bag_metadata.hpp"

namespace gvio::io::ros2 {

class McapWriter;
class SqliteWriter;

enum class Ros2Storage { kMcap, kSqlite3 };

class Ros2BagWriter {
 public:
  // compression: "none", "lz4" or "zstd" (MCAP chunks; sqlite3 stores messages as they are).
  // The storage file is written under a temporary name and renamed by close(). Throws Ros2Error.
  Ros2BagWriter(const std::filesystem::path& folder, const std::string& name, Ros2Storage storage,
                const std::string& compression);
  ~Ros2BagWriter();
  Ros2BagWriter(const Ros2BagWriter&) = delete;
  Ros2BagWriter& operator=(const Ros2BagWriter&) = delete;

  // A topic of a ROS 2 type with a known definition (ros2MessageDefinition); returns its id.
  std::size_t addTopic(const std::string& name, const std::string& type);
  void write(std::size_t topic, std::int64_t t_ns, const std::vector<std::uint8_t>& cdr);
  // Closes the storage file and writes metadata.yaml (atomically).
  void close();

 private:
  std::filesystem::path folder_, file_, temporary_;
  Ros2Storage storage_;
  std::unique_ptr<McapWriter> mcap_;
  std::unique_ptr<SqliteWriter> sqlite_;
  std::vector<std::int64_t> ids_;  // per topic: the MCAP channel or sqlite topic id
  std::vector<BagTopicSummary> topics_;
  BagFileSummary summary_;
};

}  // namespace gvio::io::ros2
