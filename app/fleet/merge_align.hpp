#pragma once
// gvio merge's joint alignment of overlapping drives (issue 18): before the maps are merged, the
// drives are brought into agreement where they overlap.
//  1. Each run's place database (keyframes.bin: loop features, VIO and final poses, used fixes,
//     its own kept loops) is read and carried into one local ENU frame (the first run's origin;
//     exact rigid transforms through ECEF).
//  2. Loop closure across drives (mapping/loop_closure.hpp with LoopPairs::kAcrossSegments):
//     keyframes of a later drive are queries against an earlier drive's keyframes near their
//     georeferenced positions (radius from both drives' GNSS-fused uncertainties), verified by
//     descriptor matching and PnP-RANSAC, checked for plausibility and temporal consistency.
//     Drives of different cameras are not matched with each other (logged).
//  3. One joint pose graph (fusion/global_graph.hpp, one segment per drive) over the keyframes of
//     the drives that the accepted loops join: each drive's VIO factors, its fixes with its own
//     receiver bias chain and its own loops, plus the loops between drives (robust, chi-square
//     switched).
//  4. Each joined drive's map is carried onto the joint poses (mapping/map_correction.hpp) while
//     it is spilled into tiles; how far each drive moved is reported (alignment.json).
// A drive without keyframes.bin, or with no accepted loop to another, is merged as it is.
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "fleet/merge_inputs.hpp"
#include "fusion/gnss_fusion.hpp"
#include "mapping/map_correction.hpp"
#include "run/loop_run.hpp"

namespace gvio::fleet {

struct DriveMovement {
  bool has_keyframes = false;  // keyframes.bin read
  bool aligned = false;        // in the joint graph (joined to another drive by a loop)
  std::string note;            // why not, when not aligned
  std::size_t keyframes = 0, fixes = 0, own_loops = 0;
  int loops_accepted = 0;  // accepted loops between this drive and another (either side)
  int loops_active = 0;    // ... kept by the joint graph
  // How far its keyframes moved (joint pose against the pose its map was built with).
  double moved_mean_m = 0.0, moved_p95_m = 0.0, moved_max_m = 0.0, rotated_max_deg = 0.0;
};

struct MergeAlignment {
  bool attempted = false;             // merge.align and two or more drives
  bool solved = false;                // the joint graph ran
  std::vector<DriveMovement> drives;  // per run, in merge order
  // Per run: the correction of its map, when it moved.
  std::vector<std::optional<mapping::MapCorrection>> corrections;
  std::size_t pairs_in_radius = 0, verified = 0, accepted = 0, active = 0;
  fusion::GlobalGraphResult graph;
  double ms_detection = 0.0;
  std::string csv;    // alignment_loops.csv
  std::string error;  // why the alignment failed (the drives were merged as they are)
};

// Reads every run's keyframes.bin (InputError for a malformed one), detects and verifies loops
// between the drives and solves the joint graph. `loops` and `fusion` are the configuration's
// loops.* and fusion.* (detection thresholds, graph and VIO noise).
MergeAlignment alignDrives(const std::vector<MergeRun>& runs, const run::LoopStageConfig& loops,
                           const fusion::FusionConfig& fusion);

// alignment_loops.csv's first line: loops.csv's columns after query_drive,candidate_drive.
std::string alignmentLoopsHeader();

nlohmann::json alignmentJson(const std::vector<MergeRun>& runs, const MergeAlignment& a);

}  // namespace gvio::fleet
