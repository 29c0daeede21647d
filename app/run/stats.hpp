#pragma once
// Small run statistics for report.json: per-frame timing summaries and the process's peak memory.
#include <chrono>
#include <vector>

namespace gvio::run {

struct TimingSummary {
  double mean = 0.0, p95 = 0.0, max = 0.0;  // ms; all 0 without samples
};

// p95 is the nearest-rank 95th percentile (the smallest sample >= 95 % of all samples).
TimingSummary summarizeTimings(std::vector<double> samples_ms);

// Wall-clock milliseconds since `start`.
double msSince(std::chrono::steady_clock::time_point start);

// Peak resident set size of this process so far (getrusage ru_maxrss), MiB.
double peakRssMb();

}  // namespace gvio::run
