#pragma once
// `gvio merge`: georeferenced runs merged into one grid of square UTM tiles (merge_tile.hpp,
// merge_index.hpp). Two passes: each run's map.pcd in turn, converted to the first run's UTM zone
// (fusion/enu_utm_grid.hpp) and spilled per tile to a scratch folder; then each tile in turn. Peak
// memory: one run's map.pcd while it is read, then one tile.
#include <filesystem>
#include <vector>

#include "fleet/fleet_config.hpp"
#include "fleet/merge_index.hpp"

namespace gvio::fleet {

struct MergeRequest {
  std::vector<std::filesystem::path> runs;  // run folders or fleet folders
  std::filesystem::path out_dir;
  MergeConfig config;
};

// Throws InvalidInput (naming the file) for a run that cannot be merged; nothing is half-written
// (every file is replaced atomically; tiles of an earlier merge into the same folder that this
// one did not write are removed at the end).
MergeSummary runMerge(const MergeRequest& request);

}  // namespace gvio::fleet
