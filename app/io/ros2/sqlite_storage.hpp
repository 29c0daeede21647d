#pragma once
// rosbag2's sqlite3 storage (.db3, the default before Iron) through Debian's libsqlite3:
//   topics(id INTEGER PRIMARY KEY, name, type, serialization_format, offered_qos_profiles
//          [, type_description_hash])
//   messages(id INTEGER PRIMARY KEY, topic_id, timestamp, data BLOB)
// (rosbag2_storage_default_plugins, sqlite_storage.cpp; schema versions 1-4 share these columns.)
// The reader opens the file read-only; message bytes stay in the file until asked for.
#include <filesystem>
#include <map>
#include <memory>
#include <mutex>
#include <string>

#include "io/ros2/storage.hpp"

struct sqlite3;
struct sqlite3_stmt;

namespace gvio::io::ros2 {

class SqliteStorage final : public StorageFile {
 public:
  explicit SqliteStorage(const std::filesystem::path& file);  // throws Ros2Error
  ~SqliteStorage() override;
  SqliteStorage(const SqliteStorage&) = delete;
  SqliteStorage& operator=(const SqliteStorage&) = delete;

  const std::vector<StoredTopic>& topics() const override { return topics_; }
  const std::vector<StoredMessage>& messages() const override { return messages_; }
  std::vector<std::uint8_t> read(std::size_t message) const override;
  MessageHead head(std::size_t message) const override;
  std::vector<std::string> warnings() const override { return warnings_; }

 private:
  void readTopics(std::map<std::int64_t, std::size_t>& topic_of_id);
  void readMessageIndex(const std::map<std::int64_t, std::size_t>& topic_of_id);
  // Up to `limit` bytes of row `rowid`'s data from offset 0 (the whole blob for limit = 0).
  std::vector<std::uint8_t> blob(std::int64_t rowid, std::size_t limit) const;

  sqlite3* db_ = nullptr;
  std::vector<StoredTopic> topics_;
  std::vector<StoredMessage> messages_;
  std::vector<std::int64_t> rowids_;  // per message
  std::vector<std::string> warnings_;
  mutable std::mutex mutex_;  // one connection, used by one thread at a time
};

// Writes a .db3 the way rosbag2 does (schema version 3: the schema and metadata tables, topics
// with offered QoS profiles); messages inserted in one transaction, committed by close().
class SqliteWriter {
 public:
  explicit SqliteWriter(const std::filesystem::path& file);  // throws Ros2Error
  ~SqliteWriter();
  SqliteWriter(const SqliteWriter&) = delete;
  SqliteWriter& operator=(const SqliteWriter&) = delete;

  std::int64_t addTopic(const std::string& name, const std::string& type);  // serialised as cdr
  void write(std::int64_t topic_id, std::int64_t t_ns, const std::vector<std::uint8_t>& data);
  void close();

 private:
  void exec(const char* sql);

  sqlite3* db_ = nullptr;
  sqlite3_stmt* insert_ = nullptr;
  std::int64_t next_topic_id_ = 1;
};

}  // namespace gvio::io::ros2
