#pragma once
// gvio run without camera frames: GNSS/INS (fusion::GnssIns) over the dataset's IMU samples and
// fixes, its run-folder files (trajectory.tum, trajectory_lla.csv, georef.json, gnss_fixes.csv) and
// report.json, with the evaluation against the dataset's truth when it is in the same ENU frame:
// the fused trajectory and, for comparison, the raw fixes at their own stamps.
#include <filesystem>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "eval/metrics.hpp"
#include "fusion/gnss_ins.hpp"
#include "fusion/gnss_screening.hpp"
#include "io/dataset.hpp"
#include "odometry/measurements.hpp"
#include "run/coverage.hpp"

namespace gvio::run {

struct InsRunResult {
  fusion::InsConfig config;
  fusion::Lla origin;  // of the local ENU frame
  fusion::ScreeningCounts screening;
  fusion::InsStats stats;
  fusion::InsState final_state;
  double time_offset_sigma_s = 0.0;  // final 1-sigma of the estimated receiver time offset
  Trajectory fused;                  // T_enu_b after every IMU sample from initialisation on
  double wall_s = 0.0;
};

// True when `gvio run` should run GNSS/INS: IMU samples and fixes but no camera frames.
bool wantsGnssIns(const io::Dataset& dataset);

// The screened fixes and IMU samples in time order through the filter. `origin` nullopt: the
// truth's ENU origin when the dataset has one, else the first usable fix. Throws InvalidInput when
// no fix is usable.
InsRunResult runGnssIns(const io::Dataset& dataset, const fusion::InsConfig& config,
                        const std::optional<fusion::Lla>& origin);

struct InsEvaluation {
  // The fused body positions against the truth at the truth's stamps (evo's association, 10 ms),
  // no alignment: horizontal (east, north) and 3-D errors.
  std::optional<eval::Stats> fused_h, fused_3d;
  // The raw fixes against the truth body position interpolated at each fix's stamp, as a
  // positioning solution on their own would be scored (no latency or lever-arm correction).
  std::optional<eval::Stats> raw_h, raw_3d;
  std::string error;  // why there is no evaluation, else ""
};

// Poses in the local ENU frame at `from` re-expressed in the one at `to` (identity when equal).
Trajectory reexpressEnu(const Trajectory& poses, const fusion::Lla& from, const fusion::Lla& to);

// `truth` in the run's ENU frame (reexpressEnu to run.origin).
InsEvaluation evaluateGnssIns(const InsRunResult& run, const Trajectory& truth);

// trajectory.tum, trajectory_lla.csv, georef.json and gnss_fixes.csv, atomically.
void writeGnssInsOutputs(const std::filesystem::path& out, const InsRunResult& run);

struct InsReportContext {
  std::string command_line;
  std::string gnss_requested;
  nlohmann::json gnss_noise;     // --gnss-noise applied to the fixes, null when none
  std::string imu_noise_source;  // "dataset" or "config"
  ImuNoise imu_noise;            // the model the filter used
  double peak_rss_mb = 0.0;
  const InsEvaluation* evaluation = nullptr;  // null: no truth in the run's frame
};

// How much of the IMU's span the GNSS/INS trajectory covers (run/coverage.hpp).
Coverage insCoverage(const io::Dataset& dataset, const InsRunResult& run);

nlohmann::json gnssInsReport(const io::Dataset& dataset, const InsRunResult& run,
                             const InsReportContext& context);

}  // namespace gvio::run
