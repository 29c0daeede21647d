#include "io/ros2/ros2_bag.hpp"

#include <fmt/format.h>
#include <zstd.h>

#include <algorithm>

#include "io/input_error.hpp"
#include "io/ros2/bag_metadata.hpp"
#include "io/ros2/mcap_records.hpp"
#include "io/ros2/ros2_error.hpp"
#include "io/ros2/ros2_messages.hpp"

namespace gvio::io::ros2 {
namespace {
namespace fs = std::filesystem;

bool isStorageFile(const fs::path& p) {
  return p.extension() == ".mcap" || p.extension() == ".db3";
}

// Without metadata.yaml: the folder's storage files in name order (rosbag2 names splits
// <bag>_0, <bag>_1, ...; a name sort puts _10 before _2, so the number is compared as a number).
std::vector<fs::path> storageFilesOf(const fs::path& folder) {
  std::vector<fs::path> files;
  for (const auto& entry : fs::directory_iterator(folder)) {
    if (entry.is_regular_file() && isStorageFile(entry.path())) files.push_back(entry.path());
  }
  const auto split_number = [](const fs::path& p) {
    const std::string stem = p.stem().string();
    const std::size_t us = stem.find_last_of('_');
    const std::string digits = us == std::string::npos ? "" : stem.substr(us + 1);
    const bool numeric =
        !digits.empty() && digits.size() < 9 &&
        std::all_of(digits.begin(), digits.end(), [](char c) { return c >= '0' && c <= '9'; });
    return std::make_pair(numeric ? stem.substr(0, us) : stem, numeric ? std::stoi(digits) : -1);
  };
  std::sort(files.begin(), files.end(), [&](const fs::path& a, const fs::path& b) {
    return split_number(a) < split_number(b);
  });
  return files;
}

// A zstd frame (rosbag2's per-message compression) expanded. The frame states its size
// (rosbag2's compressor writes it); MCAP's chunk decompressor bounds that claim (1 GiB, zstd's
// greatest ratio) before it allocates and checks the output against it.
std::vector<std::uint8_t> zstdExpanded(const std::vector<std::uint8_t>& frame) {
  const unsigned long long size = ZSTD_getFrameContentSize(frame.data(), frame.size());
  if (size == ZSTD_CONTENTSIZE_ERROR || size == ZSTD_CONTENTSIZE_UNKNOWN) {
    throw Ros2Error("a zstd-compressed message without a valid stated size");
  }
  return mcap::decompress("zstd", frame, size, 0, "a zstd-compressed message");
}

}  // namespace

bool looksLikeRos2Bag(const fs::path& path) {
  std::error_code ec;
  if (fs::is_directory(path, ec)) return hasBagMetadata(path);
  return looksLikeMcap(path) || looksLikeSqlite(path);
}

Ros2Bag::Ros2Bag(const fs::path& path) {
  std::error_code ec;
  if (!fs::is_directory(path, ec)) {
    open(path);
    return;
  }
  if (!hasBagMetadata(path)) {
    const std::vector<fs::path> found = storageFilesOf(path);
    if (found.empty()) throw InputError(path, 0, "no metadata.yaml and no .mcap or .db3 file");
    warnings_.push_back(
        fmt::format("{}: no metadata.yaml: read its {} storage file(s) in name order",
                    path.string(), found.size()));
    for (const fs::path& f : found) open(f);
    return;
  }
  const BagMetadata meta = readBagMetadata(path);
  const fs::path meta_file = path / "metadata.yaml";
  if (meta.storage_identifier != "mcap" && meta.storage_identifier != "sqlite3") {
    throw InputError(meta_file, 0,
                     fmt::format("storage_identifier '{}': gvio reads mcap and sqlite3 bags",
                                 meta.storage_identifier));
  }
  if (meta.compression_mode == "FILE" || meta.compression_mode == "file") {
    throw InputError(meta_file, 0,
                     "compression_mode FILE (each storage file zstd-compressed as a whole): "
                     "decompress them first (`zstd -d FILE.zstd`, then list the results in "
                     "relative_file_paths) or record with MESSAGE compression");
  }
  message_compression_ = meta.compression_mode == "MESSAGE" || meta.compression_mode == "message";
  if (message_compression_ && meta.compression_format != "zstd") {
    throw InputError(
        meta_file, 0,
        fmt::format("compression_format '{}': only zstd is read", meta.compression_format));
  }
  for (const std::string& rel : meta.relative_file_paths) {
    fs::path file = path / rel;
    // rosbag2 before Foxy listed paths with the bag folder's name in front.
    if (!fs::exists(file, ec) && fs::exists(path / fs::path(rel).filename(), ec)) {
      file = path / fs::path(rel).filename();
    }
    if (!fs::exists(file, ec)) {
      throw InputError(meta_file, 0,
                       fmt::format("lists storage file {}, which is missing (a split bag must be "
                                   "complete; remove it from relative_file_paths to read the rest)",
                                   rel));
    }
    open(file);
  }
}

void Ros2Bag::open(const fs::path& file) {
  std::unique_ptr<StorageFile> storage;
  try {
    storage = openStorageFile(file);
  } catch (const Ros2Error& e) {
    throw InputError(file, 0, e.what());
  }
  const std::string kind = looksLikeMcap(file) ? "mcap" : "sqlite3";
  storage_ = storage_.empty() || storage_ == kind ? kind : "mixed";
  for (const std::string& w : storage->warnings()) {
    warnings_.push_back(fmt::format("{}: {}", file.string(), w));
  }
  const std::size_t file_index = files_.size();
  std::vector<std::size_t> joined(storage->topics().size());
  for (std::size_t t = 0; t < storage->topics().size(); ++t) {
    const StoredTopic& st = storage->topics()[t];
    auto it = std::find_if(topics_.begin(), topics_.end(),
                           [&](const Ros2Topic& x) { return x.name == st.name; });
    if (it == topics_.end()) {
      topics_.push_back({st.name, st.type, st.serialization_format, {}});
      it = topics_.end() - 1;
    } else if (it->type != st.type) {
      throw InputError(
          file, 0,
          fmt::format("topic {} is {} here but {} in an earlier file", st.name, st.type, it->type));
    }
    joined[t] = static_cast<std::size_t>(it - topics_.begin());
  }
  const auto& messages = storage->messages();
  for (std::size_t m = 0; m < messages.size(); ++m) {
    topics_[joined.at(messages[m].topic)].messages.push_back({file_index, m});
  }
  files_.push_back(file);
  storages_.push_back(std::move(storage));
}

const Ros2Topic* Ros2Bag::topic(const std::string& name) const {
  for (const Ros2Topic& t : topics_) {
    if (t.name == name) return &t;
  }
  return nullptr;
}

std::vector<std::uint8_t> Ros2Bag::read(const Ros2Topic& topic, std::size_t index) const {
  const Ros2Topic::Ref& ref = topic.messages.at(index);
  std::vector<std::uint8_t> bytes = storages_.at(ref.file)->read(ref.message);
  return message_compression_ ? zstdExpanded(bytes) : bytes;
}

std::int64_t Ros2Bag::logTimeNs(const Ros2Topic& topic, std::size_t index) const {
  const Ros2Topic::Ref& ref = topic.messages.at(index);
  return storages_.at(ref.file)->messages().at(ref.message).log_time_ns;
}

std::int64_t Ros2Bag::headerStampNs(const Ros2Topic& topic, std::size_t index) const {
  if (message_compression_) {
    const std::vector<std::uint8_t> bytes = read(topic, index);
    return ros2::headerStampNs(bytes.data(), bytes.size());
  }
  const Ros2Topic::Ref& ref = topic.messages.at(index);
  const MessageHead head = storages_.at(ref.file)->head(ref.message);
  return ros2::headerStampNs(head.bytes.data(), head.size);
}

}  // namespace gvio::io::ros2
