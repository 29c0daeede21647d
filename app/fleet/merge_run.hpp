#pragma once
// `gvio merge`: georeferenced runs merged into one grid of square UTM tiles (merge_tile.hpp,
// merge_index.hpp), after the joint alignment of the drives (merge_align.hpp; alignment.json and
// alignment_loops.csv). Two passes: each run's map.pcd in turn, converted to the first run's UTM
// zone (fusion/enu_utm_grid.hpp) and spilled per tile to a scratch folder; then each tile in turn.
// Peak memory: one run's map.pcd while it is read, then one tile.
#include <filesystem>
#include <vector>

#include "fleet/fleet_config.hpp"
#include "fleet/merge_index.hpp"
#include "fusion/gnss_fusion.hpp"
#include "run/loop_run.hpp"

namespace gvio::fleet {

struct MergeRequest {
  std::vector<std::filesystem::path> runs;  // run folders or fleet folders
  std::filesystem::path out_dir;
  MergeConfig config;
  // The joint alignment's loop detection and graph (loops.*) and VIO noise (fusion.*).
  run::LoopStageConfig loops;
  fusion::FusionConfig fusion;
};

// Throws InvalidInput (naming the file) for a run that cannot be merged; nothing is half-written
// (every file is replaced atomically; tiles of an earlier merge into the same folder that this
// one did not write are removed at the end).
MergeSummary runMerge(const MergeRequest& request);

}  // namespace gvio::fleet
