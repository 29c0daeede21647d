#pragma once
// What `gvio merge` merges: run folders (or fleet folders, which stand for their complete runs),
// each georeferenced (georef.json) with a map (map.pcd), and the one frame they are merged in.
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "export/georef.hpp"
#include "fleet/fleet_config.hpp"
#include "fusion/geodesy.hpp"

namespace gvio::fleet {

struct MergeRun {
  std::filesystem::path dir;
  std::string name;  // the folder's name (unique among the runs)
  exporter::Georef georef;
  std::uint16_t point_source_id = 0;  // 1, 2, ... in the order given: the LAS "flight line"
};

// Expands and checks the --runs arguments: a folder with fleet.json stands for its drives whose
// state is "complete" (in the fleet's order); any other folder is one run. Throws InputError for
// a missing folder, a run without georef.json or map.pcd (naming the file), a run given twice, a
// fleet without a complete drive, or more than 65535 runs.
std::vector<MergeRun> resolveMergeRuns(const std::vector<std::filesystem::path>& args);

// The merged map's frame: the first run's UTM zone and hemisphere (EPSG 326ZZ/327ZZ) for the LAS
// tiles and the tile grid; a local "map" frame for PCD and OctoMap (float coordinates), the UTM
// coordinates less those of `map_origin` (the first run's ENU origin): Autoware's
// LocalCartesianUTM projector.
struct MergeFrame {
  fusion::Utm crs;  // zone, north; easting/northing of map_origin
  fusion::Lla map_origin;
  Eigen::Vector3d origin_utm = Eigen::Vector3d::Zero();  // E, N, h of map_origin
};

// Throws InvalidInput naming the run whose origin lies more than config.max_zone_distance_km
// outside the first run's zone (transverse Mercator's scale error grows with the square of that
// distance): those are merged separately, never silently mixed. Runs in a neighbouring zone
// within that distance are reprojected into the first run's zone (logged).
MergeFrame chooseMergeFrame(const std::vector<MergeRun>& runs, const MergeConfig& config);

// How far (km) a point lies outside UTM zone `zone`'s 6-degree band (0 inside it).
double kmOutsideZone(const fusion::Lla& lla, int zone);

}  // namespace gvio::fleet
