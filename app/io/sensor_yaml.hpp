#pragma once
// YAML sensor files as Kalibr and the ASL/EuRoC tools write them, for the readers that take
// calibration from them (io/euroc, io/kalibr). Errors are InputError with the file and line.
#include <yaml-cpp/yaml.h>

#include <cstddef>
#include <filesystem>
#include <string>
#include <vector>

#include "io/input_error.hpp"
#include "odometry/measurements.hpp"

namespace gvio::io {

// The file parsed as one YAML mapping. Kalibr writes "%YAML:1.0", which is not valid YAML 1.2:
// that directive is dropped before parsing.
YAML::Node loadSensorYaml(const std::filesystem::path& file);

// read(): reads a parsed sensor file. yaml-cpp throws its own exception for a node of the wrong
// kind (a scalar where a mapping goes); that becomes an InputError naming the file and line.
template <typename Fn>
auto readingYaml(const std::filesystem::path& file, Fn&& read) {
  try {
    return read();
  } catch (const YAML::Exception& e) {
    throw InputError(file, e.mark.is_null() ? 0 : static_cast<std::size_t>(e.mark.line + 1), e.msg);
  }
}

// The line of `node` for error messages (0 when the node is absent).
std::size_t lineOf(const YAML::Node& node);

// root[key] as a list of exactly `count` values of type T.
template <typename T>
std::vector<T> yamlList(const YAML::Node& root, const char* key, std::size_t count,
                        const std::filesystem::path& file) {
  const YAML::Node node = root[key];
  if (!node || !node.IsSequence() || node.size() != count) {
    throw InputError(
        file, lineOf(node),
        "'" + std::string(key) + "' must be a list of " + std::to_string(count) + " numbers");
  }
  try {
    return node.as<std::vector<T>>();
  } catch (const YAML::Exception&) {
    throw InputError(file, lineOf(node), "'" + std::string(key) + "' holds a non-numeric value");
  }
}

// The pinhole part of a camera block, as Kalibr's camchain and the ASL sensor.yaml both write it:
// resolution [w h] and intrinsics [fu fv pu pv], all positive (else InputError at the block's
// line, naming the camera). Distortion and extrinsics are left to the caller.
CameraModel pinholeCamera(const YAML::Node& block, const std::string& name,
                          const std::filesystem::path& file);

}  // namespace gvio::io
