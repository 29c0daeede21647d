#pragma once
// The merge's second pass, one tile at a time: its LAS 1.4 (UTM, WGS 84 heights, point source ID
// = drive), PCD (map frame: x y z intensity point_source_id source) and OctoMap .bt (map frame,
// the voxels the points fall in marked occupied), and how well the drives agree inside it.
#include <array>
#include <cstdint>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "fleet/fleet_config.hpp"
#include "fleet/merge_inputs.hpp"
#include "fleet/tile_spill.hpp"

namespace gvio::fleet {

// Agreement of one drive's dense points with the reference drive's (in each tile, the first drive
// of the merge that has dense points there): for each of its points (an even sample) at
// least kOverlapRadiusM inside its tile with a reference point within kOverlapRadiusM (the
// overlap), the distance to the nearest one; kept as a 1 mm histogram.
struct DriveAgreement {
  // A drive's dense points of a tile are sampled evenly: every kQueryStride-th, and at most
  // kMaxQueriesPerTile of them.
  static constexpr std::size_t kQueryStride = 8;
  static constexpr std::size_t kMaxQueriesPerTile = 4000;
  static constexpr double kOverlapRadiusM = 1.0;
  static constexpr double kWithinM = 0.2;
  static constexpr int kBins = 1000;
  std::uint64_t dense_points = 0;  // compared: sampled dense points away from tile borders
  std::uint64_t overlap = 0;
  std::uint64_t within = 0;  // of the overlap, within kWithinM
  std::vector<std::uint64_t> histogram = std::vector<std::uint64_t>(kBins, 0);

  void add(double distance_m);
  [[nodiscard]] double medianM() const;  // of the overlap (bin centre); 0 when empty
};

struct TileResult {
  TileKey key;
  std::string name;  // "E<easting>_N<northing>" of the south-west corner, metres
  std::uint64_t points = 0;
  std::map<std::uint16_t, std::uint64_t> points_per_drive;
  std::array<double, 3> min_utm{}, max_utm{};  // as the LAS header stores them
  bool octomap = false;
  std::string octomap_note;  // why there is no .bt
  std::size_t occupied_voxels = 0;
};

std::string tileName(const TileSpill& spill, const TileKey& key);

// Writes DIR/tiles/NAME.{las,pcd,bt} for one tile's points (atomically) and adds its drives'
// agreement to `agreement` (keyed by point source ID).
TileResult writeTile(const std::filesystem::path& out_dir, const MergeFrame& frame,
                     const TileSpill& spill, const TileKey& key, const MergeConfig& config,
                     std::map<std::uint16_t, DriveAgreement>& agreement);

}  // namespace gvio::fleet
