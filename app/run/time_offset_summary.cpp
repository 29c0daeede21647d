#include "run/time_offset_summary.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

namespace gvio::run {
namespace {

double median(std::vector<double> v) {
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  if (v.size() % 2 == 1) return *mid;
  return 0.5 * (*mid + *std::max_element(v.begin(), mid));
}

}  // namespace

TimeOffsetSummary summarizeTimeOffset(bool estimated, double t_d_s,
                                      const std::vector<double>& free_estimates, int held_solves) {
  TimeOffsetSummary s;
  s.t_d_s = t_d_s;
  s.final_t_d_s = t_d_s;
  s.free_solves = static_cast<int>(free_estimates.size());
  s.held_solves = held_solves;
  const int solves = s.free_solves + s.held_solves;
  s.observed_fraction = solves > 0 ? static_cast<double>(s.free_solves) / solves : 0.0;
  if (!estimated) {
    s.status = "not estimated";
    return s;
  }
  if (s.free_solves < kTimeOffsetMinFreeSolves ||
      s.observed_fraction < kTimeOffsetMinObservedFraction) {
    s.status = "not observed";
    return s;
  }
  s.status = "estimated";
  const std::vector<double> late(free_estimates.begin() + s.free_solves / 2, free_estimates.end());
  const double m = median(late);
  s.t_d_s = m;
  std::vector<double> deviation;
  deviation.reserve(late.size());
  for (const double x : late) deviation.push_back(std::abs(x - m));
  s.sigma_s = 1.4826 * median(deviation);
  return s;
}

TimeOffsetSummary vioTimeOffset(const VioRunResult& run) {
  return summarizeTimeOffset(run.time_offset_estimated, run.time_offset_s,
                             run.time_offset_free_estimates, run.counters.time_offset_held_solves);
}

std::string timeOffsetText(const TimeOffsetSummary& s) {
  if (s.status == "estimated") {
    return fmt::format("camera-IMU time offset {:.1f} +- {:.1f} ms", 1e3 * s.t_d_s,
                       1e3 * s.sigma_s);
  }
  if (s.status == "not observed") {
    return fmt::format("camera-IMU time offset not observed (held in {:.0f} % of {} solves)",
                       100.0 * (1.0 - s.observed_fraction), s.free_solves + s.held_solves);
  }
  return "";
}

nlohmann::json timeOffsetSummaryJson(const TimeOffsetSummary& s) {
  nlohmann::json j = {{"status", s.status},
                      {"t_d_s", s.t_d_s},
                      {"t_d_final_s", s.final_t_d_s},
                      {"free_solves", s.free_solves},
                      {"observed_fraction", s.observed_fraction}};
  j["sigma_s"] = s.status == "estimated" ? nlohmann::json(s.sigma_s) : nlohmann::json(nullptr);
  return j;
}

}  // namespace gvio::run
