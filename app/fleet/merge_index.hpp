#pragma once
// The merged map's index files, beside tiles/:
//   tiles.json                    the CRS, the map frame, every tile (files, points per drive,
//                                 bounds), every drive (points, agreement with the others)
//   pointcloud_map_metadata.yaml  Autoware's divided-map index: tile size, each PCD's (x_min,
//                                 y_min) in the map frame
//   map_projector_info.yaml       Autoware's projector: LocalCartesianUTM at the map origin
//   tiles.geojson                 RFC 7946: tile footprints (Polygon) and the drives' tracks
//                                 (LineString, from trajectory_lla.csv, carried as the map was)
#include <filesystem>
#include <map>
#include <vector>

#include <nlohmann/json.hpp>

#include "fleet/merge_inputs.hpp"
#include "fleet/merge_tile.hpp"
#include "fusion/geodesy.hpp"

namespace gvio::fleet {

struct MergeSummary {
  double tile_size_m = 0.0;
  std::vector<TileResult> tiles;
  std::map<std::uint16_t, std::uint64_t> points_per_drive;
  std::map<std::uint16_t, DriveAgreement> agreement;
  // Per drive (point source ID): its track, a vertex per 2 m, where its map was placed (the joint
  // alignment's correction applied as to its points); none for a run without trajectory_lla.csv.
  std::map<std::uint16_t, std::vector<fusion::Lla>> tracks;
  std::uint64_t points = 0;
  double wall_s = 0.0, points_per_s = 0.0, peak_rss_mb = 0.0;
};

// A run's trajectory_lla.csv as lat/lon/h vertices, thinned to one per 2 m; a line it cannot
// parse is an InputError naming it (the file is the run's own output).
std::vector<fusion::Lla> readTrack(const std::filesystem::path& csv);

nlohmann::json tilesJson(const std::vector<MergeRun>& runs, const MergeFrame& frame,
                         const MergeSummary& summary);

// Writes the four index files atomically; the tracks are summary.tracks.
void writeMergeIndex(const std::filesystem::path& out_dir, const std::vector<MergeRun>& runs,
                     const MergeFrame& frame, const MergeSummary& summary);

}  // namespace gvio::fleet
