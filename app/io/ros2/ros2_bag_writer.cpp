#include "io/ros2/ros2_bag_writer.hpp"

#include <algorithm>
#include <limits>

#include "io/atomic_write.hpp"
#include "io/ros2/mcap_writer.hpp"
#include "io/ros2/ros2_error.hpp"
#include "io/ros2/ros2_messages.hpp"
#include "io/ros2/sqlite_storage.hpp"

namespace gvio::io::ros2 {
namespace fs = std::filesystem;

namespace {

McapCompression mcapCompression(const std::string& name) {
  if (name == "none") return McapCompression::kNone;
  if (name == "lz4") return McapCompression::kLz4;
  if (name == "zstd") return McapCompression::kZstd;
  throw Ros2Error("MCAP compression '" + name + "' (expected none, lz4 or zstd)");
}

}  // namespace

Ros2BagWriter::Ros2BagWriter(const fs::path& folder, const std::string& name, Ros2Storage storage,
                             const std::string& compression)
    : folder_(folder), storage_(storage) {
  const std::string file = name + (storage == Ros2Storage::kMcap ? "_0.mcap" : "_0.db3");
  file_ = folder / file;
  temporary_ = folder / (file + ".tmp");
  std::error_code ec;
  fs::remove(temporary_, ec);
  summary_.relative_path = file;
  summary_.start_ns = std::numeric_limits<std::int64_t>::max();
  if (storage == Ros2Storage::kMcap) {
    mcap_ = std::make_unique<McapWriter>(temporary_, mcapCompression(compression));
  } else {
    sqlite_ = std::make_unique<SqliteWriter>(temporary_);
  }
}

Ros2BagWriter::~Ros2BagWriter() = default;

std::size_t Ros2BagWriter::addTopic(const std::string& name, const std::string& type) {
  if (mcap_) {
    const std::uint16_t schema = mcap_->addSchema(type, "ros2msg", ros2MessageDefinition(type));
    // rosbag2_storage_mcap records each topic's QoS as channel metadata; gvio's readers ignore it.
    ids_.push_back(mcap_->addChannel(name, schema, "cdr", {{"offered_qos_profiles", ""}}));
  } else {
    ids_.push_back(sqlite_->addTopic(name, type));
  }
  topics_.push_back({name, type, 0});
  return topics_.size() - 1;
}

void Ros2BagWriter::write(std::size_t topic, std::int64_t t_ns,
                          const std::vector<std::uint8_t>& cdr) {
  if (t_ns < 0) throw Ros2Error("a message stamped before 1970");
  if (mcap_) {
    const auto t = static_cast<std::uint64_t>(t_ns);
    mcap_->write(static_cast<std::uint16_t>(ids_.at(topic)), t, t, cdr.data(), cdr.size());
  } else {
    sqlite_->write(ids_.at(topic), t_ns, cdr);
  }
  ++topics_.at(topic).message_count;
  ++summary_.message_count;
  summary_.start_ns = std::min(summary_.start_ns, t_ns);
  summary_.end_ns = std::max(summary_.end_ns, t_ns);
}

void Ros2BagWriter::close() {
  if (mcap_) mcap_->close();
  if (sqlite_) sqlite_->close();
  std::error_code ec;
  fs::rename(temporary_, file_, ec);
  if (ec) throw Ros2Error("cannot rename " + temporary_.string() + ": " + ec.message());
  writeTextAtomic(
      folder_ / "metadata.yaml",
      bagMetadataYaml(storage_ == Ros2Storage::kMcap ? "mcap" : "sqlite3", {summary_}, topics_));
}

}  // namespace gvio::io::ros2
