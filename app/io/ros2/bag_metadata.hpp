#pragma once
// A ROS 2 bag folder's metadata.yaml (rosbag2_storage/bag_metadata.hpp, versions 1-9): the storage
// plugin, the files of a split recording, and whole-file or per-message compression. Counts and
// durations are the recorder's and only cross-checked; the messages themselves are the truth.
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace gvio::io::ros2 {

struct BagMetadata {
  int version = 0;
  std::string storage_identifier;  // mcap, sqlite3
  std::vector<std::string> relative_file_paths;
  std::string compression_format;  // "" or zstd
  std::string compression_mode;    // "", NONE, FILE, MESSAGE
  std::uint64_t message_count = 0;
};

// True when the folder holds a metadata.yaml.
bool hasBagMetadata(const std::filesystem::path& folder);

// Throws InputError naming metadata.yaml and the line of a missing or malformed key.
BagMetadata readBagMetadata(const std::filesystem::path& folder);

// What one storage file held, for writing metadata.yaml.
struct BagFileSummary {
  std::string relative_path;
  std::int64_t start_ns = 0, end_ns = 0;
  std::uint64_t message_count = 0;
};
struct BagTopicSummary {
  std::string name, type;
  std::uint64_t message_count = 0;
};

// metadata.yaml as `ros2 bag record` writes it (version 5: the layout Humble reads and newer
// releases still accept), uncompressed.
std::string bagMetadataYaml(const std::string& storage_identifier,
                            const std::vector<BagFileSummary>& files,
                            const std::vector<BagTopicSummary>& topics);

}  // namespace gvio::io::ros2
