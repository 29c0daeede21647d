#pragma once
// What gvio run says of the camera-IMU time offset t_d (vio.estimate_time_offset): estimated with
// an uncertainty, or not observed. The estimator holds t_d while the window's motion cannot
// observe it (constant rate and specific force, Li and Mourikis 2014); a drive that held it in
// most solves, or solved it freely only a few times, has not observed it, and its value is the
// prior's, not a measurement. Otherwise the estimate is the median of its free solves over the
// second half of them, and its uncertainty their robust spread (1.4826 x MAD): the estimator's
// value wanders with the window's excitation and the tracker's noise (on the seed-3 drives at a
// 20 ms lag the last value was 1.2-4.2 ms off, the late half's median 0.5-1.5 ms off), so its
// last value is one draw of that wander, not the drive's answer.
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "run/vio_runner.hpp"

namespace gvio::run {

struct TimeOffsetSummary {
  std::string status;        // "estimated", "not observed" or "not estimated"
  double t_d_s = 0.0;        // the late free solves' median; the final value when not observed
  double final_t_d_s = 0.0;  // the estimator's value after the last solve
  double sigma_s = 0.0;      // only with "estimated"
  int free_solves = 0, held_solves = 0;
  double observed_fraction = 0.0;  // free / (free + held)
};

inline constexpr int kTimeOffsetMinFreeSolves = 30;
inline constexpr double kTimeOffsetMinObservedFraction = 0.2;

TimeOffsetSummary summarizeTimeOffset(bool estimated, double t_d_s,
                                      const std::vector<double>& free_estimates, int held_solves);

// The run's: its free solves' estimates and its held solves.
TimeOffsetSummary vioTimeOffset(const VioRunResult& run);

// "time offset 19.8 +- 0.3 ms", "time offset not observed (held in 93 % of solves)", "" when not
// estimated.
std::string timeOffsetText(const TimeOffsetSummary& s);

nlohmann::json timeOffsetSummaryJson(const TimeOffsetSummary& s);

}  // namespace gvio::run
