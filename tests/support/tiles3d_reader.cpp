#include "support/tiles3d_reader.hpp"

#include <cstring>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <stdexcept>

namespace gvio::test {
namespace {
namespace fs = std::filesystem;
using nlohmann::json;

[[noreturn]] void fail(const fs::path& file, const std::string& what) {
  throw std::runtime_error(file.string() + ": " + what);
}

std::uint32_t u32(const std::string& b, std::size_t at) {
  std::uint32_t v = 0;
  std::memcpy(&v, b.data() + at, 4);
  return v;
}

template <typename T>
std::vector<T> column(const fs::path& file, const std::string& bin, const json& def, std::size_t n,
                      std::size_t components) {
  const std::size_t offset = def.at("byteOffset").get<std::size_t>();
  if (offset % sizeof(T) != 0) fail(file, "a byteOffset not aligned to its component");
  if (offset + n * components * sizeof(T) > bin.size()) fail(file, "a property past its body");
  std::vector<T> v(n * components);
  std::memcpy(v.data(), bin.data() + offset, v.size() * sizeof(T));
  return v;
}

void readTile(const fs::path& dir, const json& j, int parent, Tileset& out) {
  TilesetTile t;
  t.parent = parent;
  const json& box = j.at("boundingVolume").at("box");
  if (box.size() != 12) fail(dir / "tileset.json", "a box without 12 numbers");
  for (std::size_t k = 0; k < 12; ++k) t.box[k] = box[k].get<double>();
  t.geometric_error = j.at("geometricError").get<double>();
  if (j.contains("refine")) t.refine = j["refine"].get<std::string>();
  if (j.contains("content")) {
    t.uri = j["content"].at("uri").get<std::string>();
    t.content = readPnts(dir / t.uri);
  }
  const int index = static_cast<int>(out.tiles.size());
  out.tiles.push_back(std::move(t));
  if (j.contains("children")) {
    for (const json& c : j["children"]) readTile(dir, c, index, out);
  }
}

}  // namespace

PntsTile readPnts(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) fail(file, "cannot open");
  const std::string b((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (b.size() < 28 || b.compare(0, 4, "pnts") != 0) fail(file, "no pnts header");
  if (u32(b, 4) != 1) fail(file, "version is not 1");
  if (u32(b, 8) != b.size()) fail(file, "byteLength is not the file's size");
  const std::size_t ftj = u32(b, 12), ftb = u32(b, 16), btj = u32(b, 20), btb = u32(b, 24);
  if (28 + ftj + ftb + btj + btb != b.size()) fail(file, "section lengths do not add up");
  if ((28 + ftj) % 8 || ftb % 8 || (28 + ftj + ftb + btj) % 8 || btb % 8) {
    fail(file, "a section not padded to 8 bytes");
  }
  const json ft = json::parse(b.substr(28, ftj));
  const std::string ft_bin = b.substr(28 + ftj, ftb);
  PntsTile t;
  const std::size_t n = ft.at("POINTS_LENGTH").get<std::size_t>();
  if (ft.contains("RTC_CENTER")) {
    for (int k = 0; k < 3; ++k) t.rtc_center[k] = ft["RTC_CENTER"][k].get<double>();
  }
  const std::vector<float> pos = column<float>(file, ft_bin, ft.at("POSITION"), n, 3);
  for (std::size_t i = 0; i < n; ++i) {
    t.p_ecef.push_back(t.rtc_center + Eigen::Vector3d(pos[3 * i], pos[3 * i + 1], pos[3 * i + 2]));
  }
  if (ft.contains("RGB")) {
    const auto rgb = column<std::uint8_t>(file, ft_bin, ft["RGB"], n, 3);
    for (std::size_t i = 0; i < n; ++i)
      t.rgb.push_back({rgb[3 * i], rgb[3 * i + 1], rgb[3 * i + 2]});
  }
  if (btj > 0) {
    const json bt = json::parse(b.substr(28 + ftj + ftb, btj));
    const std::string bt_bin = b.substr(28 + ftj + ftb + btj, btb);
    for (const char* name : {"intensity", "drive_id"}) {
      if (!bt.contains(name)) continue;
      if (bt[name].at("componentType") != "UNSIGNED_SHORT" || bt[name].at("type") != "SCALAR") {
        fail(file, std::string(name) + " is not an UNSIGNED_SHORT SCALAR");
      }
      (std::string(name) == "intensity" ? t.intensity : t.drive_id) =
          column<std::uint16_t>(file, bt_bin, bt[name], n, 1);
    }
  }
  return t;
}

Tileset readTileset(const fs::path& dir) {
  std::ifstream in(dir / "tileset.json");
  if (!in) fail(dir / "tileset.json", "cannot open");
  const json j = json::parse(in);
  Tileset out;
  out.version = j.at("asset").at("version").get<std::string>();
  out.geometric_error = j.at("geometricError").get<double>();
  readTile(dir, j.at("root"), -1, out);
  return out;
}

bool boxContains(const std::array<double, 12>& box, const Eigen::Vector3d& p, double slack_m) {
  const Eigen::Vector3d d = p - Eigen::Vector3d(box[0], box[1], box[2]);
  for (int a = 0; a < 3; ++a) {
    const Eigen::Vector3d axis(box[3 + 3 * a], box[4 + 3 * a], box[5 + 3 * a]);
    const double half = axis.norm();
    if (std::abs(d.dot(axis / half)) > half + slack_m) return false;
  }
  return true;
}

}  // namespace gvio::test
