// The message definitions an MCAP file's schemas hold for ROS 2 ("ros2msg" encoding,
// https://mcap.dev/spec/registry#ros2msg), composed as rosbag2_storage_mcap's
// MessageDefinitionCache::get_full_text does: the type's .msg text, then each dependency not yet
// written, depth first and in name order (its std::set), as "\n", a line of 80 '=', "MSG: pkg/Type"
// and that type's text. The texts are those of ROS 2 Jazzy's .msg files with their comments left
// out (field lines, constants and default values kept); Humble's differ only in NavSatStatus's
// STATUS_UNKNOWN / SERVICE_UNKNOWN constants and status's default, which Jazzy added.
#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <set>
#include <string>
#include <string_view>

#include "io/ros2/ros2_error.hpp"
#include "io/ros2/ros2_messages.hpp"

namespace gvio::io::ros2 {

namespace {

struct Definition {
  std::string_view type;  // pkg/Type, as a dependency is named
  std::string_view text;
};

constexpr std::array kDefinitions{
    Definition{"builtin_interfaces/Time", "int32 sec\nuint32 nanosec\n"},
    Definition{"std_msgs/Header", "builtin_interfaces/Time stamp\nstring frame_id\n"},
    Definition{"geometry_msgs/Vector3", "float64 x\nfloat64 y\nfloat64 z\n"},
    Definition{"geometry_msgs/Quaternion", "float64 x 0\nfloat64 y 0\nfloat64 z 0\nfloat64 w 1\n"},
    Definition{"geometry_msgs/Transform", "Vector3 translation\nQuaternion rotation\n"},
    Definition{"geometry_msgs/TransformStamped",
               "std_msgs/Header header\nstring child_frame_id\nTransform transform\n"},
    Definition{"tf2_msgs/TFMessage", "geometry_msgs/TransformStamped[] transforms\n"},
    Definition{"sensor_msgs/Image",
               "std_msgs/Header header\n"
               "uint32 height\n"
               "uint32 width\n"
               "string encoding\n"
               "uint8 is_bigendian\n"
               "uint32 step\n"
               "uint8[] data\n"},
    Definition{"sensor_msgs/CompressedImage",
               "std_msgs/Header header\nstring format\nuint8[] data\n"},
    Definition{"sensor_msgs/Imu",
               "std_msgs/Header header\n"
               "geometry_msgs/Quaternion orientation\n"
               "float64[9] orientation_covariance\n"
               "geometry_msgs/Vector3 angular_velocity\n"
               "float64[9] angular_velocity_covariance\n"
               "geometry_msgs/Vector3 linear_acceleration\n"
               "float64[9] linear_acceleration_covariance\n"},
    Definition{"sensor_msgs/NavSatStatus",
               "int8 STATUS_UNKNOWN = -2\n"
               "int8 STATUS_NO_FIX =  -1\n"
               "int8 STATUS_FIX =      0\n"
               "int8 STATUS_SBAS_FIX = 1\n"
               "int8 STATUS_GBAS_FIX = 2\n"
               "int8 status -2\n"
               "uint16 SERVICE_UNKNOWN = 0\n"
               "uint16 SERVICE_GPS =     1\n"
               "uint16 SERVICE_GLONASS = 2\n"
               "uint16 SERVICE_COMPASS = 4\n"
               "uint16 SERVICE_GALILEO = 8\n"
               "uint16 service\n"},
    Definition{"sensor_msgs/NavSatFix",
               "std_msgs/Header header\n"
               "NavSatStatus status\n"
               "float64 latitude\n"
               "float64 longitude\n"
               "float64 altitude\n"
               "float64[9] position_covariance\n"
               "uint8 COVARIANCE_TYPE_UNKNOWN = 0\n"
               "uint8 COVARIANCE_TYPE_APPROXIMATED = 1\n"
               "uint8 COVARIANCE_TYPE_DIAGONAL_KNOWN = 2\n"
               "uint8 COVARIANCE_TYPE_KNOWN = 3\n"
               "uint8 position_covariance_type\n"},
    Definition{"sensor_msgs/RegionOfInterest",
               "uint32 x_offset\nuint32 y_offset\nuint32 height\nuint32 width\nbool do_rectify\n"},
    Definition{"sensor_msgs/CameraInfo",
               "std_msgs/Header header\n"
               "uint32 height\n"
               "uint32 width\n"
               "string distortion_model\n"
               "float64[] d\n"
               "float64[9]  k\n"
               "float64[9]  r\n"
               "float64[12] p\n"
               "uint32 binning_x\n"
               "uint32 binning_y\n"
               "RegionOfInterest roi\n"},
};

const Definition* find(std::string_view type) {
  for (const Definition& definition : kDefinitions) {
    if (definition.type == type) return &definition;
  }
  return nullptr;
}

bool isPrimitive(std::string_view type) {
  constexpr std::array<std::string_view, 14> kPrimitives{
      "bool",  "byte",   "char",  "float32", "float64", "int8",   "uint8",
      "int16", "uint16", "int32", "uint32",  "int64",   "uint64", "string"};
  for (const std::string_view primitive : kPrimitives) {
    if (type == primitive) return true;
  }
  return false;
}

// The non-primitive field types of a .msg text, package-qualified: the first word of each line
// (array brackets dropped), as rosbag2_storage_mcap's MSG_FIELD_TYPE_REGEX picks it.
std::set<std::string> dependencies(std::string_view text, std::string_view package) {
  std::set<std::string> out;
  std::size_t begin = 0;
  while (begin < text.size()) {
    const std::size_t end = std::min(text.find('\n', begin), text.size());
    const std::string_view line = text.substr(begin, end - begin);
    begin = end + 1;
    const std::string_view word = line.substr(0, line.find_first_of(" ["));
    if (word.empty() || isPrimitive(word)) continue;
    out.insert(word.find('/') == std::string_view::npos ? fmt::format("{}/{}", package, word)
                                                        : std::string(word));
  }
  return out;
}

// get_full_text's append_recursive: the text, then every dependency not yet `seen`.
std::string fullText(const Definition& definition, std::set<std::string>& seen) {
  std::string out(definition.text);
  const std::string_view package = definition.type.substr(0, definition.type.find('/'));
  for (const std::string& dependency : dependencies(definition.text, package)) {
    if (!seen.insert(dependency).second) continue;
    const Definition* nested = find(dependency);
    if (nested == nullptr) throw Ros2Error("no definition of " + dependency);  // a table defect
    out += "\n" + std::string(80, '=') + "\nMSG: " + dependency + "\n";
    out += fullText(*nested, seen);
  }
  return out;
}

}  // namespace

std::string ros2MessageDefinition(const std::string& type) {
  const Definition* definition = find(ros1TypeName(type));
  if (definition == nullptr) {
    throw Ros2Error(fmt::format("no message definition for type '{}'", type));
  }
  std::set<std::string> seen;
  return fullText(*definition, seen);
}

std::string ros1TypeName(const std::string& type) {
  // pkg/msg/Type: the interface kind "msg" is what ROS 2 adds to the ROS 1 name.
  const std::size_t first = type.find('/');
  if (first == std::string::npos) return type;
  const std::size_t second = type.find('/', first + 1);
  if (second == std::string::npos || type.find('/', second + 1) != std::string::npos) return type;
  if (type.compare(first + 1, second - first - 1, "msg") != 0) return type;
  return type.substr(0, first) + type.substr(second);
}

}  // namespace gvio::io::ros2
