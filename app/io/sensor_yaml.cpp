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

}  // namespace gvio::io
