#pragma once
// report.json of `gvio run` (DESIGN.md section 4): what ran on what, counts, per-frame timings,
// memory, GNSS use, estimator events and, with ground truth, the evaluation.
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "io/dataset.hpp"
#include "odometry/measurements.hpp"
#include "run/coverage.hpp"
#include "run/evaluation.hpp"
#include "run/gnss_run.hpp"
#include "run/vio_runner.hpp"

namespace gvio::run {

struct ReportContext {
  std::string command_line;
  std::string gnss_requested = "off";  // the --gnss value as given
  nlohmann::json gnss_noise;           // --gnss-noise applied to the fixes, null when none
  nlohmann::json map;                  // run/map_run.hpp mapReport, null without a map
  nlohmann::json loops;                // run/loop_run.hpp loopsReport, null without loop closure
  std::string imu_noise_source;        // "dataset" or "config"; empty when the mode has no IMU
  std::optional<ImuNoise> imu_noise;   // the model the estimator used; none without an IMU
  double peak_rss_mb = 0.0;
  const EvaluationOutcome* evaluation = nullptr;  // null: the dataset has no ground truth
  // The loop-closed trajectory in the VIO world (trajectory.tum without GNSS), SE(3) aligned as
  // `evaluation`; null when not run.
  const EvaluationOutcome* evaluation_loop_closed = nullptr;
  const GnssRunResult* gnss = nullptr;                 // null: no GNSS fusion ran
  const UnalignedOutcome* evaluation_fused = nullptr;  // null: not evaluated
  // The causal (online) fused trajectory when trajectory.tum is the smoothed one; else null.
  const UnalignedOutcome* evaluation_fused_online = nullptr;
};

// report.json's "dataset": path, format, variant, sensor counts, IMU rate, ground truth source
// (shared by the VIO and the GNSS/INS reports).
nlohmann::json datasetJson(const io::Dataset& dataset);

// How much of the dataset's frames the VIO trajectory covers (run/coverage.hpp).
Coverage vioCoverage(const io::Dataset& dataset, const VioRunResult& run);

nlohmann::json buildReport(const io::Dataset& dataset, const VioRunResult& run,
                           const ReportContext& context);

}  // namespace gvio::run
