#include "io/sensor_yaml.hpp"

#include <fstream>
#include <sstream>

namespace gvio::io {

YAML::Node loadSensorYaml(const std::filesystem::path& file) {
  std::ifstream in(file);
  if (!in) throw InputError(file, 0, "file not found");
  std::stringstream text;
  std::string line;
  bool first = true;
  while (std::getline(in, line)) {
    if (first && line.rfind("%YAML", 0) == 0) line = "#" + line;
    first = false;
    text << line << '\n';
  }
  try {
    YAML::Node root = YAML::Load(text.str());
    if (!root.IsMap()) throw InputError(file, 0, "expected a YAML mapping of sensor parameters");
    return root;
  } catch (const YAML::Exception& e) {
    throw InputError(file, static_cast<std::size_t>(e.mark.line + 1), e.msg);
  }
}

std::size_t lineOf(const YAML::Node& node) {
  return node ? static_cast<std::size_t>(node.Mark().line + 1) : 0;
}

CameraModel pinholeCamera(const YAML::Node& block, const std::string& name,
                          const std::filesystem::path& file) {
  CameraModel cam;
  cam.name = name;
  const auto res = yamlList<int>(block, "resolution", 2, file);
  const auto k = yamlList<double>(block, "intrinsics", 4, file);
  cam.width_px = res[0];
  cam.height_px = res[1];
  cam.fx = k[0];
  cam.fy = k[1];
  cam.cx = k[2];
  cam.cy = k[3];
  if (cam.width_px <= 0 || cam.height_px <= 0 || !(cam.fx > 0.0) || !(cam.fy > 0.0)) {
    throw InputError(file, lineOf(block), name + ": resolution and focal lengths must be positive");
  }
  return cam;
}

}  // namespace gvio::io
