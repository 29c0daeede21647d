#include "run/stats.hpp"

#include <sys/resource.h>

#include <algorithm>
#include <cmath>
#include <numeric>

namespace gvio::run {

TimingSummary summarizeTimings(std::vector<double> samples_ms) {
  TimingSummary s;
  if (samples_ms.empty()) return s;
  std::sort(samples_ms.begin(), samples_ms.end());
  const auto n = static_cast<double>(samples_ms.size());
  s.mean = std::accumulate(samples_ms.begin(), samples_ms.end(), 0.0) / n;
  const auto rank = static_cast<std::size_t>(std::ceil(0.95 * n));  // 1-based nearest rank
  s.p95 = samples_ms[std::max<std::size_t>(rank, 1) - 1];
  s.max = samples_ms.back();
  return s;
}

double msSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
      .count();
}

double peakRssMb() {
  rusage usage{};
  if (getrusage(RUSAGE_SELF, &usage) != 0) return 0.0;
  return static_cast<double>(usage.ru_maxrss) / 1024.0;  // Linux reports KiB
}

}  // namespace gvio::run
