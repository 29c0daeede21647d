#include "fleet/merged_tiles3d.hpp"

#include <cmath>
#include <map>
#include <utility>
#include <vector>

#include "fleet/merged_map.hpp"
#include "fusion/geodesy.hpp"

namespace gvio::fleet {
namespace {

constexpr double kCellM = 100.0;

// UTM (zone, hemisphere) plus the map origin's offsets -> ENU at the origin, affine per cell.
class MapToEnu {
 public:
  explicit MapToEnu(const MergedMap& map)
      : map_(map), enu_(fusion::utmToLla(utmOf(Eigen::Vector2d::Zero()), map.origin_utm.z())) {}

  [[nodiscard]] const fusion::Lla& origin() const { return enu_.origin(); }

  Eigen::Vector3d operator()(const Eigen::Vector3d& p_map) {
    const std::pair<long, long> key{std::lround(std::floor(p_map.x() / kCellM)),
                                    std::lround(std::floor(p_map.y() / kCellM))};
    auto it = cells_.find(key);
    if (it == cells_.end()) it = cells_.emplace(key, cellAt(key)).first;
    const Cell& c = it->second;
    return c.p_enu + c.J * (p_map - c.p_map);
  }

 private:
  struct Cell {
    Eigen::Vector3d p_map, p_enu;
    Eigen::Matrix3d J;  // d p_enu / d p_map at the cell's centre (central differences)
  };

  [[nodiscard]] fusion::Utm utmOf(const Eigen::Vector2d& p_map) const {
    return {map_.utm_zone, map_.utm_north, map_.origin_utm.x() + p_map.x(),
            map_.origin_utm.y() + p_map.y()};
  }

  [[nodiscard]] Eigen::Vector3d exact(const Eigen::Vector3d& p_map) const {
    return enu_.toEnu(fusion::utmToLla(utmOf(p_map.head<2>()), map_.origin_utm.z() + p_map.z()));
  }

  [[nodiscard]] Cell cellAt(const std::pair<long, long>& key) const {
    Cell c;
    c.p_map = {(static_cast<double>(key.first) + 0.5) * kCellM,
               (static_cast<double>(key.second) + 0.5) * kCellM, 0.0};
    c.p_enu = exact(c.p_map);
    constexpr double h = 10.0;
    for (int a = 0; a < 3; ++a) {
      Eigen::Vector3d d = Eigen::Vector3d::Zero();
      d[a] = h;
      c.J.col(a) = (exact(c.p_map + d) - exact(c.p_map - d)) / (2.0 * h);
    }
    return c;
  }

  const MergedMap& map_;
  fusion::EnuFrame enu_;
  std::map<std::pair<long, long>, Cell> cells_;
};

}  // namespace

exporter::Tiles3dSummary exportMergedTiles3d(const std::filesystem::path& map_dir,
                                             const std::filesystem::path& out) {
  const MergedMap map = readMergedMap(map_dir, 0);
  MapToEnu to_enu(map);
  std::vector<exporter::TilesPoint> points;
  points.reserve(map.points.size());
  for (std::size_t k = 0; k < map.points.size(); ++k) {
    points.push_back({to_enu(map.points[k].cast<double>()),
                      static_cast<std::uint16_t>(map.intensity[k] * 257U), map.point_source_id[k]});
  }
  return exporter::writeTiles3d(out, to_enu.origin(), points);
}

}  // namespace gvio::fleet
