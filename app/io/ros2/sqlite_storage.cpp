#include "io/ros2/sqlite_storage.hpp"

#include <fmt/format.h>
#include <sqlite3.h>

#include <algorithm>
#include <limits>

#include "io/ros2/ros2_error.hpp"

namespace gvio::io::ros2 {
namespace {

// A prepared statement, finalised on scope exit.
class Statement {
 public:
  Statement(sqlite3* db, const char* sql) {
    if (sqlite3_prepare_v2(db, sql, -1, &stmt_, nullptr) != SQLITE_OK) {
      const std::string what = sqlite3_errmsg(db);
      sqlite3_finalize(stmt_);
      throw Ros2Error(fmt::format("not a rosbag2 sqlite3 file ({})", what));
    }
  }
  ~Statement() { sqlite3_finalize(stmt_); }
  Statement(const Statement&) = delete;
  Statement& operator=(const Statement&) = delete;

  // True while a row is there; throws on an error (e.g. a damaged page).
  bool step(sqlite3* db) {
    const int rc = sqlite3_step(stmt_);
    if (rc == SQLITE_ROW) return true;
    if (rc == SQLITE_DONE) return false;
    throw Ros2Error(fmt::format("sqlite3: {}", sqlite3_errmsg(db)));
  }
  std::string text(int column) const {
    const unsigned char* t = sqlite3_column_text(stmt_, column);
    return t == nullptr ? std::string() : std::string(reinterpret_cast<const char*>(t));
  }
  std::int64_t integer(int column) const { return sqlite3_column_int64(stmt_, column); }
  sqlite3_stmt* get() const { return stmt_; }

 private:
  sqlite3_stmt* stmt_ = nullptr;
};

}  // namespace

SqliteStorage::SqliteStorage(const std::filesystem::path& file) {
  if (sqlite3_open_v2(file.c_str(), &db_, SQLITE_OPEN_READONLY, nullptr) != SQLITE_OK) {
    const std::string what = db_ ? sqlite3_errmsg(db_) : "out of memory";
    sqlite3_close(db_);
    db_ = nullptr;
    throw Ros2Error("cannot open as sqlite3: " + what);
  }
  try {
    std::map<std::int64_t, std::size_t> topic_of_id;
    readTopics(topic_of_id);
    readMessageIndex(topic_of_id);
  } catch (...) {
    sqlite3_close(db_);
    db_ = nullptr;
    throw;
  }
}

SqliteStorage::~SqliteStorage() {
  sqlite3_close(db_);
}

void SqliteStorage::readTopics(std::map<std::int64_t, std::size_t>& topic_of_id) {
  Statement s(db_, "SELECT id, name, type, serialization_format FROM topics ORDER BY id");
  while (s.step(db_)) {
    topic_of_id[s.integer(0)] = topics_.size();
    topics_.push_back({s.text(1), s.text(2), s.text(3)});
  }
}

void SqliteStorage::readMessageIndex(const std::map<std::int64_t, std::size_t>& topic_of_id) {
  // rosbag2 replays in timestamp order (its read query orders by timestamp, then id).
  Statement s(db_, "SELECT id, topic_id, timestamp FROM messages ORDER BY timestamp, id");
  std::size_t orphans = 0;
  while (s.step(db_)) {
    const auto topic = topic_of_id.find(s.integer(1));
    if (topic == topic_of_id.end()) {
      ++orphans;
      continue;
    }
    rowids_.push_back(s.integer(0));
    messages_.push_back({topic->second, s.integer(2)});
  }
  if (orphans > 0) {
    warnings_.push_back(fmt::format(
        "{} messages name a topic id the topics table does not hold: skipped", orphans));
  }
}

std::vector<std::uint8_t> SqliteStorage::blob(std::int64_t rowid, std::size_t limit) const {
  const std::lock_guard lock(mutex_);
  sqlite3_blob* b = nullptr;
  if (sqlite3_blob_open(db_, "main", "messages", "data", rowid, 0, &b) != SQLITE_OK) {
    const std::string what = sqlite3_errmsg(db_);
    sqlite3_blob_close(b);
    throw Ros2Error(fmt::format("message row {}: {}", rowid, what));
  }
  const int total = sqlite3_blob_bytes(b);
  const int count = limit == 0 ? total : std::min(total, static_cast<int>(limit));
  std::vector<std::uint8_t> out(static_cast<std::size_t>(std::max(count, 0)));
  const int rc = count > 0 ? sqlite3_blob_read(b, out.data(), count, 0) : SQLITE_OK;
  sqlite3_blob_close(b);
  if (rc != SQLITE_OK) {
    throw Ros2Error(fmt::format("message row {}: {}", rowid, sqlite3_errstr(rc)));
  }
  return out;
}

std::vector<std::uint8_t> SqliteStorage::read(std::size_t message) const {
  return blob(rowids_.at(message), 0);
}

MessageHead SqliteStorage::head(std::size_t message) const {
  MessageHead h;
  const std::vector<std::uint8_t> bytes = blob(rowids_.at(message), h.bytes.size());
  std::copy(bytes.begin(), bytes.end(), h.bytes.begin());
  h.size = bytes.size();
  return h;
}

SqliteWriter::SqliteWriter(const std::filesystem::path& file) {
  if (sqlite3_open_v2(file.c_str(), &db_, SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE, nullptr) !=
      SQLITE_OK) {
    const std::string what = db_ ? sqlite3_errmsg(db_) : "out of memory";
    sqlite3_close(db_);
    db_ = nullptr;
    throw Ros2Error("cannot create the sqlite3 file: " + what);
  }
  // rosbag2's sqlite_storage.cpp: the same tables and index (schema version 3, Humble).
  exec("PRAGMA journal_mode = MEMORY; PRAGMA synchronous = OFF;");
  exec(
      "CREATE TABLE schema(schema_version INTEGER PRIMARY KEY, ros_distro TEXT NOT NULL);"
      "INSERT INTO schema VALUES (3, 'humble');"
      "CREATE TABLE metadata(id INTEGER PRIMARY KEY, metadata_version INTEGER NOT NULL, "
      "metadata TEXT NOT NULL);"
      "CREATE TABLE topics(id INTEGER PRIMARY KEY, name TEXT NOT NULL, type TEXT NOT NULL, "
      "serialization_format TEXT NOT NULL, offered_qos_profiles TEXT NOT NULL);"
      "CREATE TABLE messages(id INTEGER PRIMARY KEY, topic_id INTEGER NOT NULL, "
      "timestamp INTEGER NOT NULL, data BLOB NOT NULL);"
      "CREATE INDEX timestamp_idx ON messages (timestamp ASC);"
      "BEGIN TRANSACTION;");
  if (sqlite3_prepare_v2(db_, "INSERT INTO messages (timestamp, topic_id, data) VALUES (?, ?, ?)",
                         -1, &insert_, nullptr) != SQLITE_OK) {
    throw Ros2Error(fmt::format("sqlite3: {}", sqlite3_errmsg(db_)));
  }
}

SqliteWriter::~SqliteWriter() {
  sqlite3_finalize(insert_);
  sqlite3_close(db_);
}

void SqliteWriter::exec(const char* sql) {
  char* error = nullptr;
  if (sqlite3_exec(db_, sql, nullptr, nullptr, &error) != SQLITE_OK) {
    const std::string what = error ? error : "unknown error";
    sqlite3_free(error);
    throw Ros2Error("sqlite3: " + what);
  }
}

std::int64_t SqliteWriter::addTopic(const std::string& name, const std::string& type) {
  const std::int64_t id = next_topic_id_++;
  Statement s(db_,
              "INSERT INTO topics (id, name, type, serialization_format, offered_qos_profiles) "
              "VALUES (?, ?, ?, 'cdr', '')");
  sqlite3_bind_int64(s.get(), 1, id);
  sqlite3_bind_text(s.get(), 2, name.c_str(), -1, SQLITE_TRANSIENT);
  sqlite3_bind_text(s.get(), 3, type.c_str(), -1, SQLITE_TRANSIENT);
  s.step(db_);
  return id;
}

void SqliteWriter::write(std::int64_t topic_id, std::int64_t t_ns,
                         const std::vector<std::uint8_t>& data) {
  if (data.size() > static_cast<std::size_t>(std::numeric_limits<int>::max())) {
    throw Ros2Error("a message of more than 2 GiB cannot be stored in sqlite3");
  }
  sqlite3_reset(insert_);
  sqlite3_bind_int64(insert_, 1, t_ns);
  sqlite3_bind_int64(insert_, 2, topic_id);
  sqlite3_bind_blob(insert_, 3, data.data(), static_cast<int>(data.size()), SQLITE_STATIC);
  if (sqlite3_step(insert_) != SQLITE_DONE) {
    throw Ros2Error(fmt::format("sqlite3: {}", sqlite3_errmsg(db_)));
  }
}

void SqliteWriter::close() {
  exec("COMMIT;");
  sqlite3_finalize(insert_);
  insert_ = nullptr;
  if (sqlite3_close(db_) != SQLITE_OK) throw Ros2Error("sqlite3: the file could not be closed");
  db_ = nullptr;
}

}  // namespace gvio::io::ros2
