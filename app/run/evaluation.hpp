#pragma once
// gvio run's self-evaluation against the dataset's ground truth, with the same code (and so the
// same numbers) as `gvio eval --align se3`: APE of the translation and RPE per 100 m of path.
#include <optional>
#include <string>

#include "eval/metrics.hpp"
#include "odometry/trajectory.hpp"

namespace gvio::run {

inline constexpr double kRpeSegmentM = 100.0;

struct RunEvaluation {
  eval::Stats ape_se3;  // translation APE (m) after SE(3) Umeyama alignment of the estimate
  // Mean translation RPE over consecutive 100 m segments of the estimate's path (evo's pairs), as
  // a percentage of 100 m; nullopt when the drive is too short for one segment pair.
  std::optional<double> rpe_100m_percent;
  double path_length_m = 0.0;  // of the ground truth over the associated poses
};

struct EvaluationOutcome {
  std::optional<RunEvaluation> result;
  std::string error;  // why there is no result (too few poses, degenerate alignment), else ""
};

// `truth` and `estimate` need timestamps; poses associate within 10 ms as evo's default.
EvaluationOutcome evaluateAgainstTruth(const Trajectory& truth, const Trajectory& estimate);

struct UnalignedOutcome {
  std::optional<eval::Stats> ape;  // translation APE (m) with no alignment at all
  std::string error;               // why there is none, else ""
};

// The fused trajectory against the truth as they are: both must be in the same frame (the local
// ENU frame of fusion.origin set to the truth's origin, as for simulated drives).
UnalignedOutcome evaluateUnaligned(const Trajectory& truth, const Trajectory& estimate);

}  // namespace gvio::run
