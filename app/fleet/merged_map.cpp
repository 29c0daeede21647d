#include "fleet/merged_map.hpp"

#include <pcl/PCLPointCloud2.h>
#include <pcl/io/pcd_io.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <optional>

#include "fusion/geodesy.hpp"
#include "io/input_error.hpp"
#include "io/quiet_pcl.hpp"
#include "io/run_dir.hpp"

namespace gvio::fleet {
namespace {

namespace fs = std::filesystem;

struct Frame {
  int zone = 0;
  bool north = true;
  double origin_e = 0.0, origin_n = 0.0, origin_h = 0.0;
};

std::uint32_t fieldOffset(const pcl::PCLPointCloud2& cloud, const std::string& name,
                          std::uint8_t type, const fs::path& file) {
  for (const auto& f : cloud.fields) {
    if (f.name == name && f.datatype == type) return f.offset;
  }
  throw io::InputError(file, 0, "tile without the field '" + name + "' gvio merge writes");
}

void readTile(const fs::path& file, std::size_t stride, MergedMap& map) {
  pcl::PCLPointCloud2 cloud;
  int rc = -1;
  {
    const io::QuietPcl quiet;
    rc = pcl::io::loadPCDFile(file.string(), cloud);
  }
  if (rc != 0) throw io::InputError(file, 0, "cannot read the tile");
  using F = pcl::PCLPointField;
  const std::uint32_t x = fieldOffset(cloud, "x", F::FLOAT32, file);
  const std::uint32_t y = fieldOffset(cloud, "y", F::FLOAT32, file);
  const std::uint32_t z = fieldOffset(cloud, "z", F::FLOAT32, file);
  const std::uint32_t id = fieldOffset(cloud, "point_source_id", F::UINT16, file);
  const std::uint32_t kind = fieldOffset(cloud, "source", F::UINT8, file);
  // Intensity (0..255 as float32) is optional: a tile without it reads as black.
  std::optional<std::uint32_t> intensity;
  for (const auto& f : cloud.fields) {
    if (f.name == "intensity" && f.datatype == F::FLOAT32) intensity = f.offset;
  }
  const std::size_t n = std::size_t{cloud.width} * cloud.height;
  if (cloud.data.size() < n * cloud.point_step) throw io::InputError(file, 0, "truncated tile");
  for (std::size_t k = 0; k < n; k += stride) {
    const std::uint8_t* p = cloud.data.data() + k * cloud.point_step;
    float v[3];
    std::memcpy(&v[0], p + x, 4);
    std::memcpy(&v[1], p + y, 4);
    std::memcpy(&v[2], p + z, 4);
    std::uint16_t drive = 0;
    std::memcpy(&drive, p + id, 2);
    if (!std::isfinite(v[0]) || !std::isfinite(v[1]) || !std::isfinite(v[2])) continue;
    map.points.emplace_back(v[0], v[1], v[2]);
    map.point_source_id.push_back(drive);
    map.source.push_back(p[kind]);
    float i = 0.0F;
    if (intensity) std::memcpy(&i, p + *intensity, 4);
    map.intensity.push_back(
        static_cast<std::uint8_t>(std::isfinite(i) ? std::clamp(i, 0.0F, 255.0F) + 0.5F : 0.0F));
  }
}

// The tracks of tiles.geojson (lon, lat, h) in the map frame.
void readTracks(const fs::path& file, const Frame& frame, MergedMap& map) {
  if (!fs::exists(file)) return;
  const nlohmann::json geo = io::readJsonObject(file);
  try {
    for (const auto& f : geo.at("features")) {
      if (f.at("geometry").at("type") != "LineString") continue;
      const auto id = f.at("properties").at("point_source_id").get<std::uint16_t>();
      for (auto& d : map.drives) {
        if (d.point_source_id != id) continue;
        for (const auto& c : f.at("geometry").at("coordinates")) {
          const fusion::Lla lla{c.at(1).get<double>(), c.at(0).get<double>(),
                                c.size() > 2 ? c.at(2).get<double>() : frame.origin_h};
          const fusion::Utm utm = fusion::llaToUtm(lla, frame.zone, frame.north);
          d.track_map.emplace_back(utm.easting_m - frame.origin_e, utm.northing_m - frame.origin_n,
                                   lla.h_ellipsoid_m - frame.origin_h);
        }
      }
    }
  } catch (const nlohmann::json::exception& e) {
    throw io::InputError(file, 0, std::string("not the GeoJSON gvio merge writes: ") + e.what());
  }
}

}  // namespace

bool isMergedMap(const fs::path& dir) {
  return fs::is_regular_file(dir / "tiles.json");
}

MergedMap readMergedMap(const fs::path& dir, std::size_t max_points) {
  const fs::path index_file = dir / "tiles.json";
  const nlohmann::json index = io::readJsonObject(index_file);
  MergedMap map;
  map.dir = dir;
  Frame frame;
  std::vector<fs::path> files;
  try {
    map.tile_size_m = index.at("tile_size_m").get<double>();
    map.utm_epsg = index.at("crs").at("epsg").get<int>();
    frame.zone = index.at("crs").at("utm_zone").get<int>();
    frame.north = index.at("crs").at("north").get<bool>();
    const auto& m = index.at("map_frame");
    frame.origin_e = m.at("origin_easting_m").get<double>();
    frame.origin_n = m.at("origin_northing_m").get<double>();
    frame.origin_h = m.at("origin_h_ellipsoid_m").get<double>();
    for (const auto& t : index.at("tiles")) {
      MergedTile tile;
      tile.name = t.at("name").get<std::string>();
      tile.sw_map = {t.at("sw_easting_m").get<double>() - frame.origin_e,
                     t.at("sw_northing_m").get<double>() - frame.origin_n};
      tile.points = t.at("points").get<std::uint64_t>();
      map.total_points += tile.points;
      const std::string pcd = t.at("files").at("pcd").get<std::string>();
      if (pcd.find("..") != std::string::npos || fs::path(pcd).is_absolute()) {
        throw io::InputError(index_file, 0, "tile file '" + pcd + "' outside the map folder");
      }
      std::error_code ec;  // a name too long for the file system names no file: missing
      if (!fs::is_regular_file(dir / pcd, ec)) {
        throw io::InputError(index_file, 0, "tile file '" + pcd + "' is listed but missing");
      }
      files.push_back(dir / pcd);
      map.tiles.push_back(tile);
    }
    for (const auto& d : index.at("drives")) {
      map.drives.push_back(
          {d.at("point_source_id").get<std::uint16_t>(), d.at("name").get<std::string>(), {}});
    }
  } catch (const nlohmann::json::exception& e) {
    throw io::InputError(index_file, 0, std::string("not a gvio merge index: ") + e.what());
  }
  if (!(map.tile_size_m > 0.0) || frame.zone < 1 || frame.zone > 60) {
    throw io::InputError(index_file, 0, "not a gvio merge index: bad tile size or UTM zone");
  }
  map.utm_zone = frame.zone;
  map.utm_north = frame.north;
  map.origin_utm = {frame.origin_e, frame.origin_n, frame.origin_h};
  if (!map.origin_utm.allFinite()) {
    throw io::InputError(index_file, 0, "not a gvio merge index: map origin not finite");
  }
  const std::size_t stride =
      max_points == 0 ? 1
                      : std::max<std::size_t>(1, (map.total_points + max_points - 1) / max_points);
  for (const auto& file : files) readTile(file, stride, map);
  readTracks(dir / "tiles.geojson", frame, map);
  return map;
}

}  // namespace gvio::fleet
