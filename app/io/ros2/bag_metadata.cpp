#include "io/ros2/bag_metadata.hpp"

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <limits>

#include "io/input_error.hpp"
#include "io/sensor_yaml.hpp"

namespace gvio::io::ros2 {
namespace {
namespace fs = std::filesystem;

constexpr const char* kMetadataFile = "metadata.yaml";

std::string scalarOr(const YAML::Node& node, const char* key, const std::string& fallback) {
  const YAML::Node n = node[key];
  return n && n.IsScalar() ? n.as<std::string>() : fallback;
}

}  // namespace

bool hasBagMetadata(const fs::path& folder) {
  std::error_code ec;
  return fs::is_regular_file(folder / kMetadataFile, ec);
}

BagMetadata readBagMetadata(const fs::path& folder) {
  const fs::path file = folder / kMetadataFile;
  return readingYaml(file, [&] {
    YAML::Node root;
    try {
      root = YAML::LoadFile(file.string());
    } catch (const YAML::BadFile&) {
      throw InputError(file, 0, "cannot be read");
    }
    const YAML::Node info = root["rosbag2_bagfile_information"];
    if (!info || !info.IsMap()) {
      throw InputError(file, 0, "no 'rosbag2_bagfile_information' mapping: not a ROS 2 bag");
    }
    BagMetadata m;
    m.version = info["version"] ? info["version"].as<int>() : 0;
    m.storage_identifier = scalarOr(info, "storage_identifier", "");
    m.compression_format = scalarOr(info, "compression_format", "");
    m.compression_mode = scalarOr(info, "compression_mode", "");
    if (info["message_count"]) m.message_count = info["message_count"].as<std::uint64_t>();
    const YAML::Node paths = info["relative_file_paths"];
    if (!paths || !paths.IsSequence() || paths.size() == 0) {
      throw InputError(file, lineOf(info),
                       "'relative_file_paths' must list the bag's storage files");
    }
    for (const YAML::Node& p : paths) {
      const std::string name = p.as<std::string>();
      // Split files live in the bag folder: a path leaving it is refused rather than followed.
      if (name.empty() || fs::path(name).is_absolute() || name.find("..") != std::string::npos) {
        throw InputError(
            file, lineOf(p),
            "relative_file_paths entry '" + name + "' is not a file of the bag folder");
      }
      m.relative_file_paths.push_back(name);
    }
    return m;
  });
}

std::string bagMetadataYaml(const std::string& storage_identifier,
                            const std::vector<BagFileSummary>& files,
                            const std::vector<BagTopicSummary>& topics) {
  std::int64_t start = std::numeric_limits<std::int64_t>::max(), end = 0;
  std::uint64_t count = 0;
  for (const BagFileSummary& f : files) {
    if (f.message_count == 0) continue;
    start = std::min(start, f.start_ns);
    end = std::max(end, f.end_ns);
    count += f.message_count;
  }
  if (count == 0) start = 0;
  std::string y = "rosbag2_bagfile_information:\n  version: 5\n";
  y += fmt::format("  storage_identifier: {}\n", storage_identifier);
  y += fmt::format("  duration:\n    nanoseconds: {}\n", end - start);
  y += fmt::format("  starting_time:\n    nanoseconds_since_epoch: {}\n", start);
  y += fmt::format("  message_count: {}\n  topics_with_message_count:\n", count);
  for (const BagTopicSummary& t : topics) {
    y += fmt::format(
        "    - topic_metadata:\n        name: {}\n        type: {}\n"
        "        serialization_format: cdr\n        offered_qos_profiles: \"\"\n"
        "      message_count: {}\n",
        t.name, t.type, t.message_count);
  }
  y += "  compression_format: \"\"\n  compression_mode: \"\"\n  relative_file_paths:\n";
  for (const BagFileSummary& f : files) y += fmt::format("    - {}\n", f.relative_path);
  y += "  files:\n";
  for (const BagFileSummary& f : files) {
    y += fmt::format(
        "    - path: {}\n      starting_time:\n        nanoseconds_since_epoch: {}\n"
        "      duration:\n        nanoseconds: {}\n      message_count: {}\n",
        f.relative_path, f.start_ns, f.end_ns - f.start_ns, f.message_count);
  }
  return y;
}

}  // namespace gvio::io::ros2
