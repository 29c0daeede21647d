#include "fleet/merged_consistency.hpp"

#include <map>

#include "fusion/enu_utm_grid.hpp"
#include "mapping/consistency.hpp"

namespace gvio::fleet {

nlohmann::json surfaceStatsJson(const mapping::SurfaceDistanceStats& s, double target_median_m) {
  return {{"n", s.n},
          {"median_m", s.median_m},
          {"mean_m", s.mean_m},
          {"p90_m", s.p90_m},
          {"rmse_m", s.rmse_m},
          {"within_m", s.within_m},
          {"fraction_within", s.fraction_within},
          {"beyond_max_distance", s.far},
          {"max_distance_m", s.max_distance_m},
          {"target_median_m", target_median_m},
          {"meets_target", s.n > 0 && s.median_m <= target_median_m}};
}

io::TriangleMesh meshInMapFrame(io::TriangleMesh mesh, const fusion::Lla& mesh_origin,
                                const MergedMap& map) {
  fusion::EnuToUtmGrid grid(mesh_origin, map.utm_zone, map.utm_north);
  for (auto& v : mesh.vertices) v = grid.toUtm(v) - map.origin_utm;
  return mesh;
}

nlohmann::json mergedConsistency(const MergedMap& map, const io::TriangleMesh& mesh_in_map,
                                 double max_distance_m, double dense_target_m,
                                 double sparse_target_m) {
  const mapping::TriangleMeshIndex surface(mesh_in_map.vertices, mesh_in_map.triangles);
  std::vector<Eigen::Vector3d> dense, sparse;
  std::map<std::uint16_t, std::vector<Eigen::Vector3d>> per_drive;
  for (std::size_t k = 0; k < map.points.size(); ++k) {
    const Eigen::Vector3d p = map.points[k].cast<double>();
    if (map.source[k] == 0) {
      sparse.push_back(p);
    } else {
      dense.push_back(p);
      per_drive[map.point_source_id[k]].push_back(p);
    }
  }
  nlohmann::json j;
  j["points_read"] = map.points.size();
  j["points_in_map"] = map.total_points;
  j["dense"] = surfaceStatsJson(
      mapping::cloudToSurface(surface, dense, max_distance_m, dense_target_m), dense_target_m);
  j["sparse"] = surfaceStatsJson(
      mapping::cloudToSurface(surface, sparse, max_distance_m, sparse_target_m), sparse_target_m);
  nlohmann::json drives = nlohmann::json::array();
  for (const auto& d : map.drives) {
    const auto it = per_drive.find(d.point_source_id);
    const auto stats = mapping::cloudToSurface(
        surface, it == per_drive.end() ? std::vector<Eigen::Vector3d>{} : it->second,
        max_distance_m, dense_target_m);
    drives.push_back({{"point_source_id", d.point_source_id},
                      {"name", d.name},
                      {"dense", surfaceStatsJson(stats, dense_target_m)}});
  }
  j["drives"] = drives;
  return j;
}

}  // namespace gvio::fleet
