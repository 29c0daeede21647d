#include "io/gps_time.hpp"

#include <array>

namespace gvio::io {
namespace {

// GPST - UTC from each date on (UTC midnight, days since 1970-01-01 times 86400, plus the offset
// already accumulated so that the switch happens at the GPST instant of that midnight).
struct Step {
  std::int64_t utc_unix_s;  // the first UTC second with the new offset
  int gps_minus_utc_s;
};
constexpr std::array<Step, 18> kLeapSteps{{
    {362793600, 1},    // 1981-07-01
    {394329600, 2},    // 1982-07-01
    {425865600, 3},    // 1983-07-01
    {489024000, 4},    // 1985-07-01
    {567993600, 5},    // 1988-01-01
    {631152000, 6},    // 1990-01-01
    {662688000, 7},    // 1991-01-01
    {709948800, 8},    // 1992-07-01
    {741484800, 9},    // 1993-07-01
    {773020800, 10},   // 1994-07-01
    {820454400, 11},   // 1996-01-01
    {867715200, 12},   // 1997-07-01
    {915148800, 13},   // 1999-01-01
    {1136073600, 14},  // 2006-01-01
    {1230768000, 15},  // 2009-01-01
    {1341100800, 16},  // 2012-07-01
    {1435708800, 17},  // 2015-07-01
    {1483228800, 18},  // 2017-01-01
}};

constexpr std::int64_t kNsPerS = 1'000'000'000;

}  // namespace

int gpsMinusUtcSeconds(std::int64_t t_gpst_unix_ns) {
  int offset = 0;
  for (const Step& step : kLeapSteps) {
    // In GPST the new offset starts at the UTC midnight plus the new offset.
    if (t_gpst_unix_ns >= (step.utc_unix_s + step.gps_minus_utc_s) * kNsPerS) {
      offset = step.gps_minus_utc_s;
    }
  }
  return offset;
}

std::int64_t gpstToUtcNs(std::int64_t t_gpst_unix_ns) {
  return t_gpst_unix_ns - gpsMinusUtcSeconds(t_gpst_unix_ns) * kNsPerS;
}

std::int64_t gpsWeekTowToGpstUnixNs(std::int64_t week, std::int64_t tow_ns) {
  return (kGpsEpochUnixS + week * kSecondsPerWeek) * kNsPerS + tow_ns;
}

}  // namespace gvio::io
