#pragma once
// GPS time (GPST) <-> UTC for GNSS solution files. GPST has no leap seconds: it ran 15 s ahead of
// UTC in 2011 and has been 18 s ahead since 2017-01-01 (IERS Bulletin C; the table below is every
// leap second since the GPS epoch, 1980-01-06 00:00:00 UTC). A table, not a package: RTKLIB
// (librtklib-dev) has the same table inside its solution reader, which cannot report a bad line.
#include <cstdint>

namespace gvio::io {

inline constexpr std::int64_t kGpsEpochUnixS = 315964800;  // 1980-01-06 00:00:00 UTC
inline constexpr std::int64_t kSecondsPerWeek = 604800;

// GPST - UTC in whole seconds at the instant `t_gpst_unix_ns` (GPST expressed on the Unix time
// line, i.e. a GPST calendar time read as if it were UTC).
int gpsMinusUtcSeconds(std::int64_t t_gpst_unix_ns);

// A GPST calendar instant (read as if UTC) -> UTC nanoseconds since the Unix epoch.
std::int64_t gpstToUtcNs(std::int64_t t_gpst_unix_ns);

// GPS week and seconds of week -> the GPST instant on the Unix time line (no leap seconds yet).
std::int64_t gpsWeekTowToGpstUnixNs(std::int64_t week, std::int64_t tow_ns);

}  // namespace gvio::io
