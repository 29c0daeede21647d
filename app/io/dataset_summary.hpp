#pragma once
// What `gvio inspect` reports about a dataset: sensors, rates, time spans, counts, gaps and a
// calibration summary, as JSON (the machine-readable form) and as text for people.
#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "io/dataset.hpp"

namespace gvio::io {

struct StreamStats {
  std::size_t count = 0;
  std::int64_t t_first_ns = 0, t_last_ns = 0;
  double median_period_s = 0.0;
  double rate_hz = 0.0;  // 1 / median period
  // Intervals [t_ns, t_next_ns] longer than gap_factor x the median period.
  std::vector<std::pair<std::int64_t, std::int64_t>> gaps;
  double max_gap_s = 0.0;  // the longest period
};

StreamStats streamStats(const std::vector<std::int64_t>& stamps_ns, double gap_factor);

// An IMU noise model's four densities (inspect's summary, and report.json's "imu_noise": the model
// an estimator used, a dataset's after imu.dataset_noise_scale).
nlohmann::json imuNoiseJson(const ImuNoise& noise);

// `imu_noise` is the effective noise model (dataset's or config's) and `imu_noise_source` where
// it came from.
nlohmann::json summarizeDataset(const Dataset& dataset, double gap_factor,
                                const ImuNoise& imu_noise, const std::string& imu_noise_source);

std::string formatSummary(const nlohmann::json& summary);

// A ROS bag's topics: role, topic, type, messages, used, and the repairs (sorted, dropped,
// zero stamps); an empty array for other formats. In inspect's summary and report.json.
nlohmann::json bagTopicsJson(const Dataset& dataset);

}  // namespace gvio::io
