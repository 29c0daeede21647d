#include "fleet/merge_index.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <cmath>
#include <fstream>
#include <optional>
#include <sstream>

#include "io/atomic_write.hpp"
#include "io/input_error.hpp"

namespace gvio::fleet {
namespace {

namespace fs = std::filesystem;

nlohmann::json lonLat(const fusion::Utm& crs, double easting, double northing) {
  fusion::Utm u = crs;
  u.easting_m = easting;
  u.northing_m = northing;
  const fusion::Lla lla = fusion::utmToLla(u, 0.0);
  return {std::round(lla.lon_deg * 1e8) / 1e8, std::round(lla.lat_deg * 1e8) / 1e8};
}

std::string metadataYaml(const MergeFrame& frame, const MergeSummary& summary) {
  std::string text = fmt::format(
      "# Autoware divided point cloud map (pointcloud_map_loader): tile size and each PCD's\n"
      "# south-west corner in the map frame (UTM less the map origin's, map_projector_info.yaml)\n"
      "x_resolution: {}\ny_resolution: {}\n",
      summary.tile_size_m, summary.tile_size_m);
  for (const TileResult& t : summary.tiles) {
    text += fmt::format("{}.pcd: [{}, {}]\n", t.name,
                        static_cast<double>(t.key.i) * summary.tile_size_m - frame.origin_utm.x(),
                        static_cast<double>(t.key.j) * summary.tile_size_m - frame.origin_utm.y());
  }
  return text;
}

std::string projectorYaml(const MergeFrame& frame) {
  return fmt::format(
      "# Autoware map projector: the map frame is UTM zone {}{} (EPSG:{}) less the map origin's\n"
      "# easting/northing, heights WGS 84 ellipsoidal less the origin's\n"
      "projector_type: LocalCartesianUTM\nvertical_datum: WGS84\nmap_origin:\n"
      "  latitude: {:.10f}\n  longitude: {:.10f}\n  altitude: {:.4f}\n",
      frame.crs.zone, frame.crs.north ? "N" : "S", frame.crs.epsg(), frame.map_origin.lat_deg,
      frame.map_origin.lon_deg, frame.map_origin.h_ellipsoid_m);
}

nlohmann::json geojson(const std::vector<MergeRun>& runs, const MergeFrame& frame,
                       const MergeSummary& summary) {
  nlohmann::json features = nlohmann::json::array();
  const double s = summary.tile_size_m;
  for (const TileResult& t : summary.tiles) {
    const double e = static_cast<double>(t.key.i) * s, n = static_cast<double>(t.key.j) * s;
    nlohmann::json ring = {lonLat(frame.crs, e, n), lonLat(frame.crs, e + s, n),
                           lonLat(frame.crs, e + s, n + s), lonLat(frame.crs, e, n + s),
                           lonLat(frame.crs, e, n)};
    nlohmann::json drives = nlohmann::json::array();
    for (const auto& [id, count] : t.points_per_drive) drives.push_back(id);
    features.push_back({{"type", "Feature"},
                        {"geometry", {{"type", "Polygon"}, {"coordinates", {ring}}}},
                        {"properties",
                         {{"kind", "tile"},
                          {"name", t.name},
                          {"points", t.points},
                          {"point_source_ids", drives}}}});
  }
  for (const MergeRun& run : runs) {
    const auto it = summary.tracks.find(run.point_source_id);
    if (it == summary.tracks.end() || it->second.size() < 2) continue;
    nlohmann::json line = nlohmann::json::array();
    for (const fusion::Lla& lla : it->second) {
      line.push_back({std::round(lla.lon_deg * 1e8) / 1e8, std::round(lla.lat_deg * 1e8) / 1e8,
                      std::round(lla.h_ellipsoid_m * 1e3) / 1e3});
    }
    features.push_back(
        {{"type", "Feature"},
         {"geometry", {{"type", "LineString"}, {"coordinates", line}}},
         {"properties",
          {{"kind", "track"}, {"name", run.name}, {"point_source_id", run.point_source_id}}}});
  }
  return {{"type", "FeatureCollection"}, {"features", features}};
}

}  // namespace

std::vector<fusion::Lla> readTrack(const fs::path& csv) {
  std::vector<fusion::Lla> vertices;
  std::ifstream in(csv);
  std::string line;
  Eigen::Vector3d last = Eigen::Vector3d::Constant(std::nan(""));
  std::optional<fusion::EnuFrame> enu;  // at the first vertex: distances for the thinning
  for (std::size_t number = 1; std::getline(in, line); ++number) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream fields(line);
    std::string t, lat, lon, h;
    std::getline(fields, t, ',');
    std::getline(fields, lat, ',');
    std::getline(fields, lon, ',');
    std::getline(fields, h, ',');
    fusion::Lla lla;
    try {
      lla = {std::stod(lat), std::stod(lon), std::stod(h)};
    } catch (const std::exception&) {
      throw io::InputError(csv, number, "expected t_s,lat_deg,lon_deg,h_ellipsoid_m,...");
    }
    if (!fusion::isValidLla(lla)) throw io::InputError(csv, number, "invalid lat/lon/h");
    if (!enu) enu.emplace(lla);
    const Eigen::Vector3d p = enu->toEnu(lla);
    if (last.allFinite() && (p - last).norm() < 2.0) continue;
    last = p;
    vertices.push_back(lla);
  }
  return vertices;
}

nlohmann::json tilesJson(const std::vector<MergeRun>& runs, const MergeFrame& frame,
                         const MergeSummary& summary) {
  nlohmann::json tiles = nlohmann::json::array();
  for (const TileResult& t : summary.tiles) {
    nlohmann::json per_drive = nlohmann::json::object();
    for (const auto& [id, count] : t.points_per_drive) per_drive[std::to_string(id)] = count;
    nlohmann::json files{{"las", "tiles/" + t.name + ".las"}, {"pcd", "tiles/" + t.name + ".pcd"}};
    if (t.octomap) files["bt"] = "tiles/" + t.name + ".bt";
    nlohmann::json j{{"name", t.name},
                     {"sw_easting_m", static_cast<double>(t.key.i) * summary.tile_size_m},
                     {"sw_northing_m", static_cast<double>(t.key.j) * summary.tile_size_m},
                     {"points", t.points},
                     {"points_per_drive", per_drive},
                     {"min_utm", t.min_utm},
                     {"max_utm", t.max_utm},
                     {"occupied_voxels", t.occupied_voxels},
                     {"files", files}};
    if (!t.octomap) j["octomap_note"] = t.octomap_note;
    tiles.push_back(j);
  }
  nlohmann::json drives = nlohmann::json::array();
  for (const MergeRun& run : runs) {
    nlohmann::json d{{"point_source_id", run.point_source_id},
                     {"name", run.name},
                     {"run_dir", run.dir.string()},
                     {"utm_zone", run.georef.utm_zone},
                     {"reprojected", run.georef.utm_zone != frame.crs.zone},
                     {"points", summary.points_per_drive.count(run.point_source_id) != 0
                                    ? summary.points_per_drive.at(run.point_source_id)
                                    : 0}};
    if (const auto it = summary.agreement.find(run.point_source_id);
        it != summary.agreement.end()) {
      const DriveAgreement& a = it->second;
      d["agreement"] = {{"dense_points_compared", a.dense_points},
                        {"overlap_radius_m", DriveAgreement::kOverlapRadiusM},
                        {"overlap_points", a.overlap},
                        {"within_m", DriveAgreement::kWithinM},
                        {"within_percent", a.overlap > 0 ? 100.0 * static_cast<double>(a.within) /
                                                               static_cast<double>(a.overlap)
                                                         : 0.0},
                        {"median_m", a.medianM()},
                        {"sample",
                         {{"stride_at_least", DriveAgreement::kQueryStride},
                          {"at_most_per_tile", DriveAgreement::kMaxQueriesPerTile}}},
                        {"note",
                         "an even sample of the drive's dense points (at least overlap_radius_m "
                         "inside their tile) against the dense points of the tile's reference "
                         "drive (the first of the merge with dense points there): the nearest "
                         "within overlap_radius_m"}};
    }
    drives.push_back(d);
  }
  return {{"crs",
           {{"epsg", frame.crs.epsg()},
            {"utm_zone", frame.crs.zone},
            {"north", frame.crs.north},
            {"heights", "WGS 84 ellipsoidal"}}},
          {"map_frame",
           {{"origin_lat_deg", frame.map_origin.lat_deg},
            {"origin_lon_deg", frame.map_origin.lon_deg},
            {"origin_h_ellipsoid_m", frame.map_origin.h_ellipsoid_m},
            {"origin_easting_m", frame.origin_utm.x()},
            {"origin_northing_m", frame.origin_utm.y()},
            {"note",
             "PCD and .bt tiles: x = easting - origin_easting_m, y = northing - "
             "origin_northing_m, z = h - origin_h_ellipsoid_m; LAS tiles: UTM"}}},
          {"tile_size_m", summary.tile_size_m},
          {"points", summary.points},
          {"wall_s", summary.wall_s},
          {"points_per_s", summary.points_per_s},
          {"peak_rss_mb", summary.peak_rss_mb},
          {"tiles", tiles},
          {"drives", drives}};
}

void writeMergeIndex(const fs::path& out_dir, const std::vector<MergeRun>& runs,
                     const MergeFrame& frame, const MergeSummary& summary) {
  io::writeTextAtomic(out_dir / "tiles.json", tilesJson(runs, frame, summary).dump(2) + "\n");
  io::writeTextAtomic(out_dir / "pointcloud_map_metadata.yaml", metadataYaml(frame, summary));
  io::writeTextAtomic(out_dir / "map_projector_info.yaml", projectorYaml(frame));
  io::writeTextAtomic(out_dir / "tiles.geojson", geojson(runs, frame, summary).dump() + "\n");
}

}  // namespace gvio::fleet
