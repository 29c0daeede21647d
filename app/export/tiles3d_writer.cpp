#include "export/tiles3d_writer.hpp"

#include <algorithm>
#include <bit>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "io/atomic_write.hpp"
#include "io/input_error.hpp"
#include "odometry/error.hpp"

namespace gvio::exporter {
namespace {
namespace fs = std::filesystem;
using nlohmann::json;

static_assert(std::endian::native == std::endian::little, "3D Tiles are little-endian");

constexpr double kMinHalfAxisM = 0.01;  // a flat tile still has a box a viewer can test

// The ENU -> ECEF map, p_ecef = o + R p_enu (a local tangent plane is exactly affine).
struct EcefOfEnu {
  Eigen::Vector3d origin;
  Eigen::Matrix3d R;
  explicit EcefOfEnu(const fusion::Lla& o)
      : origin(fusion::llaToEcef(o)), R(fusion::EnuFrame(o).R_enu_ecef().transpose()) {}
};

void append(std::string& out, const void* data, std::size_t bytes) {
  out.append(static_cast<const char*>(data), bytes);
}

void padTo8(std::string& s, char with) {
  while (s.size() % 8 != 0) s.push_back(with);
}

// A JSON header padded with spaces so that what follows it starts on an 8-byte boundary of the
// file (`before`: the bytes ahead of it).
std::string paddedJson(const json& j, std::size_t before) {
  std::string s = j.dump();
  while ((before + s.size()) % 8 != 0) s.push_back(' ');
  return s;
}

json boxOf(const Eigen::AlignedBox3d& bounds_enu, const EcefOfEnu& to_ecef) {
  const Eigen::Vector3d centre = to_ecef.origin + to_ecef.R * bounds_enu.center();
  const Eigen::Vector3d half =
      (bounds_enu.sizes() / 2.0).cwiseMax(Eigen::Vector3d::Constant(kMinHalfAxisM));
  json box = json::array();
  for (int k = 0; k < 3; ++k) box.push_back(centre[k]);
  for (int a = 0; a < 3; ++a) {
    const Eigen::Vector3d axis = to_ecef.R.col(a) * half[a];
    for (int k = 0; k < 3; ++k) box.push_back(axis[k]);
  }
  return box;
}

// One .pnts tile of the points `ids`, relative to the ECEF of their bounds' centre.
std::string pntsTile(std::span<const TilesPoint> points, const std::vector<std::uint32_t>& ids,
                     const Eigen::AlignedBox3d& bounds_enu, const EcefOfEnu& to_ecef) {
  const std::size_t n = ids.size();
  const Eigen::Vector3d centre_enu = bounds_enu.center();
  const Eigen::Vector3d rtc = to_ecef.origin + to_ecef.R * centre_enu;
  std::string ft_bin, bt_bin;
  ft_bin.reserve(15 * n + 8);
  for (const std::uint32_t i : ids) {
    const Eigen::Vector3f d = (to_ecef.R * (points[i].p_enu - centre_enu)).cast<float>();
    append(ft_bin, d.data(), 12);
  }
  const std::size_t rgb_offset = ft_bin.size();
  for (const std::uint32_t i : ids) {
    const auto grey = static_cast<char>(points[i].intensity >> 8);
    ft_bin.append(3, grey);
  }
  padTo8(ft_bin, '\0');
  for (const std::uint32_t i : ids) append(bt_bin, &points[i].intensity, 2);
  padTo8(bt_bin, '\0');
  const std::size_t drive_offset = bt_bin.size();
  for (const std::uint32_t i : ids) append(bt_bin, &points[i].drive_id, 2);
  padTo8(bt_bin, '\0');

  constexpr std::size_t kHeader = 28;
  const json ft = {{"POINTS_LENGTH", n},
                   {"RTC_CENTER", {rtc.x(), rtc.y(), rtc.z()}},
                   {"POSITION", {{"byteOffset", 0}}},
                   {"RGB", {{"byteOffset", rgb_offset}}}};
  const json bt = {
      {"intensity", {{"byteOffset", 0}, {"componentType", "UNSIGNED_SHORT"}, {"type", "SCALAR"}}},
      {"drive_id",
       {{"byteOffset", drive_offset}, {"componentType", "UNSIGNED_SHORT"}, {"type", "SCALAR"}}}};
  const std::string ft_json = paddedJson(ft, kHeader);
  const std::string bt_json = paddedJson(bt, kHeader + ft_json.size() + ft_bin.size());
  const std::size_t total =
      kHeader + ft_json.size() + ft_bin.size() + bt_json.size() + bt_bin.size();
  std::string tile;
  tile.reserve(total);
  tile += "pnts";
  for (const std::size_t v :
       {std::size_t{1}, total, ft_json.size(), ft_bin.size(), bt_json.size(), bt_bin.size()}) {
    const auto u = static_cast<std::uint32_t>(v);
    append(tile, &u, 4);
  }
  tile += ft_json + ft_bin + bt_json + bt_bin;
  return tile;
}

class TilesetWriter {
 public:
  TilesetWriter(const fs::path& dir, std::span<const TilesPoint> points,
                const mapping::PointLodTree& tree, const fusion::Lla& origin)
      : dir_(dir), points_(points), tree_(tree), to_ecef_(origin) {}

  json tile(int index, Tiles3dSummary& summary) const {
    const mapping::PointLodNode& node = tree_.nodes[static_cast<std::size_t>(index)];
    summary.depth = std::max(summary.depth, node.depth);
    json t = {{"boundingVolume", {{"box", boxOf(node.bounds, to_ecef_)}}},
              {"geometricError", node.spacing_m}};
    if (!node.points.empty()) {
      const std::string uri = "tiles/" + node.name + ".pnts";
      io::writeTextAtomic(dir_ / uri, pntsTile(points_, node.points, node.bounds, to_ecef_));
      t["content"] = {{"uri", uri}};
      ++summary.tiles;
    }
    json children = json::array();
    for (const int c : node.children) {
      if (c >= 0) children.push_back(tile(c, summary));
    }
    if (!children.empty()) t["children"] = std::move(children);
    return t;
  }

 private:
  fs::path dir_;
  std::span<const TilesPoint> points_;
  const mapping::PointLodTree& tree_;
  EcefOfEnu to_ecef_;
};

}  // namespace

Tiles3dSummary writeTiles3d(const fs::path& dir, const fusion::Lla& enu_origin,
                            std::span<const TilesPoint> points,
                            const mapping::PointLodConfig& lod) {
  if (fs::exists(dir) &&
      (!fs::is_directory(dir) || (!fs::is_empty(dir) && !fs::exists(dir / "tileset.json")))) {
    throw io::InputError(dir, 0, "exists and is not a tileset folder; choose another --out");
  }
  std::vector<Eigen::Vector3d> p(points.size());
  std::transform(points.begin(), points.end(), p.begin(),
                 [](const TilesPoint& t) { return t.p_enu; });
  const mapping::PointLodTree tree = mapping::buildPointLod(p, lod);
  if (tree.nodes.empty()) throw InvalidInput("3D Tiles: the cloud has no finite point");
  Tiles3dSummary summary;
  summary.points = tree.points;
  io::writeFolderAtomic(dir, [&](const fs::path& tmp) {
    fs::create_directory(tmp / "tiles");
    const TilesetWriter writer(tmp, points, tree, enu_origin);
    json root = writer.tile(0, summary);
    root["refine"] = "ADD";
    const double extent = tree.nodes.front().cube.sizes().norm();
    const json tileset = {{"asset", {{"version", "1.0"}, {"generator", "gvio"}}},
                          {"geometricError", extent},
                          {"root", std::move(root)}};
    io::writeTextAtomic(tmp / "tileset.json", tileset.dump(1) + "\n");
  });
  return summary;
}

}  // namespace gvio::exporter
