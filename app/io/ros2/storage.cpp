#include "io/ros2/storage.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <limits>

#include "io/ros2/mcap_reader.hpp"
#include "io/ros2/mcap_records.hpp"
#include "io/ros2/ros2_error.hpp"
#include "io/ros2/sqlite_storage.hpp"
#include "io/text.hpp"

namespace gvio::io::ros2 {
namespace {
namespace fs = std::filesystem;

// An MCAP file's channels as topics (the schema name is the ROS 2 type, the channel's message
// encoding its serialisation), its messages with their log times.
class McapStorage final : public StorageFile {
 public:
  explicit McapStorage(const fs::path& file) : reader_(file) {
    std::vector<std::size_t> topic_of_channel;  // by channel id; npos: not a ROS 2 topic
    for (const McapChannel& c : reader_.channels()) {
      const McapSchema* schema = reader_.schema(c.schema_id);
      if (topic_of_channel.size() <= c.id) topic_of_channel.resize(c.id + 1U, kNone);
      topic_of_channel[c.id] = topics_.size();
      topics_.push_back({c.topic, schema ? schema->name : std::string(), c.message_encoding});
    }
    const auto& refs = reader_.messages();
    for (std::size_t i = 0; i < refs.size(); ++i) {
      const McapMessageRef& m = refs[i];
      const std::size_t topic =
          m.channel_id < topic_of_channel.size() ? topic_of_channel[m.channel_id] : kNone;
      if (topic == kNone) continue;
      if (m.log_time_ns > static_cast<std::uint64_t>(std::numeric_limits<std::int64_t>::max())) {
        throw Ros2Error(fmt::format("message {} has a log time past the year 2262", i));
      }
      messages_.push_back({topic, static_cast<std::int64_t>(m.log_time_ns)});
      refs_.push_back(i);
    }
  }
  const std::vector<StoredTopic>& topics() const override { return topics_; }
  const std::vector<StoredMessage>& messages() const override { return messages_; }
  std::vector<std::uint8_t> read(std::size_t message) const override {
    return reader_.read(reader_.messages().at(refs_.at(message)));
  }
  MessageHead head(std::size_t message) const override {
    const std::size_t i = refs_.at(message);
    MessageHead h;
    h.size = reader_.headSize(i);
    const auto& bytes = reader_.head(i);
    std::copy(bytes.begin(), bytes.begin() + static_cast<std::ptrdiff_t>(h.size), h.bytes.begin());
    return h;
  }
  // The reader already counts messages on channels no Channel record declares (skipped here).
  std::vector<std::string> warnings() const override { return reader_.warnings(); }

 private:
  static constexpr std::size_t kNone = std::numeric_limits<std::size_t>::max();
  McapReader reader_;
  std::vector<StoredTopic> topics_;
  std::vector<StoredMessage> messages_;
  std::vector<std::size_t> refs_;  // index into reader_.messages() per message
};

}  // namespace

bool looksLikeMcap(const fs::path& file) {
  return fileStartsWith(file, std::string_view(reinterpret_cast<const char*>(mcap::kMagic.data()),
                                               mcap::kMagic.size()));
}

bool looksLikeSqlite(const fs::path& file) {
  return fileStartsWith(file, std::string_view("SQLite format 3", 16));  // with its NUL
}

std::unique_ptr<StorageFile> openStorageFile(const fs::path& file) {
  std::error_code ec;
  if (!fs::is_regular_file(file, ec)) throw Ros2Error("not found");
  if (looksLikeMcap(file)) return std::make_unique<McapStorage>(file);
  if (looksLikeSqlite(file)) return std::make_unique<SqliteStorage>(file);
  throw Ros2Error("neither an MCAP file nor an sqlite3 database (ROS 2 bag storage)");
}

}  // namespace gvio::io::ros2
