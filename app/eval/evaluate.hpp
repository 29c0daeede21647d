#pragma once
// One evaluation as `evo_ape` / `evo_rpe` run it: associate, align the estimate onto the
// reference, then APE over all associated poses and (optionally) RPE over consecutive pairs.
#include <optional>

#include "eval/metrics.hpp"

namespace gvio::eval {

struct EvalOptions {
  Alignment align = Alignment::kNone;
  Relation relation = Relation::kTranslation;
  std::int64_t t_max_diff_ns = 10'000'000;  // evo --t_max_diff 0.01 s
  std::int64_t t_offset_ns = 0;             // added to the estimate's stamps
  std::optional<double> rpe_delta;          // RPE only when set
  DeltaUnit rpe_unit = DeltaUnit::kFrames;
};

struct RpeResult {
  std::vector<std::pair<std::size_t, std::size_t>> pairs;  // into the associated poses
  std::vector<double> errors;
  Stats stats;
};

struct EvalResult {
  std::size_t ref_poses = 0, est_poses = 0;
  bool paired_by_index = false;           // a side without timestamps (KITTI): pairs by index
  Sim3 alignment;                         // applied to the estimate (identity for none)
  std::vector<std::int64_t> t_ns;         // stamps of the associated poses (ref's; empty if none)
  std::vector<Eigen::Matrix4d> ref, est;  // associated poses, estimate aligned
  std::vector<std::size_t> est_index;     // each associated pose's index in the estimate
  std::vector<double> ape;
  Stats ape_stats;
  std::optional<RpeResult> rpe;
};

// Throws InvalidInput for unequal lengths without timestamps, fewer than 3 associated poses and
// degenerate alignment.
EvalResult evaluate(const Trajectory& ref, const Trajectory& est, const EvalOptions& options);

}  // namespace gvio::eval
