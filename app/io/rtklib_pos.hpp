#pragma once
// RTKLIB solution files (.pos, as RTKPOST / RNX2RTKP / RTKNAVI write them): header lines start
// with '%', the last one names the columns. Supported, as RTKLIB's manual (appendix B) lists them:
//  - time: calendar "yyyy/mm/dd hh:mm:ss.sss" or GPS week + seconds of week, in GPST, UTC or JST
//    (GPST -> UTC with the leap seconds of io/gps_time.hpp);
//  - position: latitude/longitude in degrees + ellipsoidal height with sdn, sde, sdu (and the
//    signed square roots of the covariances sdne, sdeu, sdun), or ECEF x, y, z with sdx..sdzx
//    (converted to lat/lon/h, the covariance rotated into east-north-up);
//  - Q: 1 fix, 2 float, 3 SBAS, 4 DGPS, 5 single, 6 PPP; 0 (no solution) is skipped and counted;
//  - velocities when RTKLIB wrote them (vn ve vu, or vx vy vz in ECEF): the fix's speed and course
//    over ground, as NMEA RMC gives them (GNSS/INS uses them).
// Each fix's sigma is RTKLIB's own, but never below the floor of its quality (the NMEA reader's
// dataset.nmea_uere_* values: a receiver's formal sigma is optimistic): horizontal =
// sqrt((sdn^2 + sde^2) / 2) per axis, vertical = sdu, the vertical floor times
// dataset.nmea_vertical_factor.
// Refused with InputError (file and line): an unknown column header, degrees-minutes-seconds,
// ENU baselines (relative to a base station, not georeferenced), heights above the geoid,
// malformed numbers or times, times that do not increase.
#include <cstddef>
#include <filesystem>
#include <string>
#include <vector>

#include "io/reader_config.hpp"
#include "odometry/measurements.hpp"

namespace gvio::io {

struct PosFile {
  std::vector<GnssFix> fixes;         // UTC ns since the Unix epoch, strictly increasing
  std::string time_system;            // "GPST", "UTC" or "JST"
  std::string position_format;        // "llh" or "ecef"
  std::size_t no_solution = 0;        // Q 0 lines skipped
  std::size_t with_velocity = 0;      // fixes with RTKLIB's velocity columns (speed and course)
  std::vector<std::string> warnings;  // one line per kind of skip
};

PosFile readRtklibPos(const std::filesystem::path& file, const ReaderConfig& config);

// GnssFix::quality (NMEA GGA convention) of an RTKLIB Q flag, 0 for none/unknown.
int nmeaQualityOfRtklibQ(int q);

}  // namespace gvio::io
